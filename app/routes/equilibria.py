"""``/api/v1/equilibria``: equilibrium by virtual work, stability and normal modes (notes II.A)."""

from __future__ import annotations

from fastapi import APIRouter

from app.derivations import derive_seconds
from app.routes.scenes import unknown_scene
from app.schemas import EquilibriaRequest, EquilibriaResponse, Message, ValidationErrors
from mechanics.budget import run_with_budget
from mechanics.scenes import scene_ids
from mechanics.spec import parse_spec

router = APIRouter(prefix="/api/v1", tags=["equilibria"])


def _posted(spec: dict, parameters: dict) -> dict:
    from mechanics.derive import derive_model
    from mechanics.equilibria import equilibria

    return equilibria(derive_model(spec), parameters)


@router.post(
    "/equilibria",
    response_model=EquilibriaResponse,
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {"model": ValidationErrors, "description": "A field is invalid."},
    },
    summary="Equilibria, their stability and small oscillations",
)
def post_equilibria(request: EquilibriaRequest) -> dict:
    """δW = Σ Q_j δq_j = 0 at rest, solved in closed form where sympy can (with the condition
    under which each root exists), numerically otherwise; each equilibrium linearized to
    M δq̈ + C δq̇ + K δq = 0 for its stability, frequencies and normal modes."""
    from mechanics.derive import derivation_of_scene
    from mechanics.equilibria import equilibria

    if request.scene_id is not None:
        if request.scene_id not in scene_ids():
            raise unknown_scene(request.scene_id)
        return equilibria(derivation_of_scene(request.scene_id), request.parameters)
    document = request.scene.model_dump(mode="json", by_alias=True, exclude_unset=True)
    parse_spec(document)
    return run_with_budget(_posted, document, request.parameters, seconds=derive_seconds())
