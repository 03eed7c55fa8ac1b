"""``/api/v1/check``: is a student's T, V, L, Q_j, EoM, q̈ or p_j right, and if not, where not?"""

from __future__ import annotations

from fastapi import APIRouter, Request

from app.derivations import on_scene
from app.schemas import CheckRequest, CheckResponse, Message, ValidationErrors

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
