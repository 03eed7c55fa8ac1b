"""``/api/v1/newton``: Newton's method beside Lagrange's, and the constraint forces it reveals."""

from __future__ import annotations

from fastapi import APIRouter

from app.derivations import derive_seconds
from app.routes.scenes import unknown_scene
from app.schemas import DeriveRequest, Message, NewtonResponse, ValidationErrors
from mechanics.budget import run_with_budget
from mechanics.scenes import scene_ids
from mechanics.spec import parse_spec

router = APIRouter(prefix="/api/v1", tags=["newton"])


def _posted(spec: dict) -> dict:
    from mechanics.derive import derive_model
    from mechanics.newton import newton_json

    return newton_json(derive_model(spec))


@router.post(
    "/newton",
    response_model=NewtonResponse,
    responses={404: {"model": Message}, 422: {"model": ValidationErrors}},
    summary="Newton's method and the constraint forces",
)
def post_newton(request: DeriveRequest) -> dict:
    """Σ F = m a per body in its natural frame with the constraint force as an unknown,
    projected on the virtual displacements (the same equations as Lagrange's) and solved for
    the constraint forces: a pendulum's tension, a hoop's normal force, a string's tension."""
    from mechanics.derive import derivation_of_scene
    from mechanics.newton import newton_json

    if request.scene_id is not None:
        if request.scene_id not in scene_ids():
            raise unknown_scene(request.scene_id)
        return newton_json(derivation_of_scene(request.scene_id))
    document = request.scene.model_dump(mode="json", by_alias=True, exclude_unset=True)
    parse_spec(document)
    return run_with_budget(_posted, document, seconds=derive_seconds())
