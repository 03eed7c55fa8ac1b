"""``/api/v1/check``: is a student's T, V, L, Q_j, EoM, q̈ or p_j right, and if not, where not?"""

from __future__ import annotations

from fastapi import APIRouter, Request

from app.derivations import on_scene
from app.schemas import (
    CheckRequest,
    CheckResponse,
    Message,
    PredictRequest,
    PredictResponse,
    ValidationErrors,
)

router = APIRouter(prefix="/api/v1", tags=["check"])


@router.post(
    "/check",
    response_model=CheckResponse,
    response_model_exclude_none=True,
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {"model": ValidationErrors, "description": "Unparseable answer or bad field."},
        503: {"model": Message, "description": "The check ran past its time budget."},
    },
    summary="Check a student's answer",
)
def post_check(request: CheckRequest, http: Request) -> dict:
    """Equivalence at random states backed by symbolic simplification; feedback names the
    missing or extra term, a wrong factor or sign, swapped parameters, q mixed with q̇, and terms
    whose units cannot belong to the quantity."""
    from mechanics.jobs import answer_check

    return on_scene(
        http,
        request,
        answer_check,
        request.quantity,
        request.answer,
        request.coordinate,
        request.reveal,
        what="checking this answer",
        advice="write it more simply (as the notes would) and try again",
    )


@router.post(
    "/check/predict",
    response_model=PredictResponse,
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {
            "model": ValidationErrors,
            "description": "Unparseable answer, or one that gives no motion (no q̈ in it, q̈ not "
            "linear, q̈ undetermined at the initial state): field 'answer'.",
        },
        503: {"model": Message, "description": "The prediction ran past its time budget."},
    },
    summary="What a student's answer predicts",
)
def post_predict(request: PredictRequest, http: Request) -> dict:
    """The answer (eom, accel, T, V, L or Q) as a model of its own, integrated with DOP853
    (rtol 1e-9) beside the derivation's from the same initial state: both trajectories, the time
    they part visibly, and the energy the answer's model creates or destroys, measured with the
    true E = T + V. A run that blows up says when (``student.blew_up_at``)."""
    from mechanics.jobs import answer_predict

    return on_scene(
        http,
        request,
        answer_predict,
        request.quantity,
        request.answer,
        request.coordinate,
        request.parameters,
        request.initial,
        request.t_end,
        what="predicting this answer's motion",
        advice="write it more simply (as the notes would) and try again",
    )
