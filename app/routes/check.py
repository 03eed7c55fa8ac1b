"""``/api/v1/check``: is a student's T, V, L, Q_j, EoM, q̈ or p_j right, and if not, where not?"""

from __future__ import annotations

from fastapi import APIRouter

from app.derivations import derive_seconds
from app.routes.scenes import unknown_scene
from app.schemas import CheckRequest, CheckResponse, Message, ValidationErrors
from mechanics.budget import run_with_budget
from mechanics.scenes import scene_ids
from mechanics.spec import parse_spec

router = APIRouter(prefix="/api/v1", tags=["check"])


def _check_posted(spec: dict, quantity: str, answer: str, coordinate: str | None, reveal: bool):
    from mechanics.check import check
    from mechanics.derive import derive_model

    return check(derive_model(spec), quantity, answer, coordinate).to_json(reveal)


@router.post(
    "/check",
    response_model=CheckResponse,
    response_model_exclude_none=True,
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {"model": ValidationErrors, "description": "Unparseable answer or bad field."},
    },
    summary="Check a student's answer",
)
def post_check(request: CheckRequest) -> dict:
    """Equivalence at random states backed by symbolic simplification; feedback names the
    missing or extra term, a wrong factor or sign, swapped parameters, q mixed with q̇, and terms
    whose units cannot belong to the quantity."""
    from mechanics.check import check
    from mechanics.derive import derivation_of_scene

    args = (request.quantity, request.answer, request.coordinate)
    if request.scene_id is not None:
        if request.scene_id not in scene_ids():
            raise unknown_scene(request.scene_id)
        return check(derivation_of_scene(request.scene_id), *args).to_json(request.reveal)
    document = request.scene.model_dump(mode="json", by_alias=True, exclude_unset=True)
    parse_spec(document)
    return run_with_budget(_check_posted, document, *args, request.reveal, seconds=derive_seconds())
