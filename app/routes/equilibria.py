"""``/api/v1/equilibria``: equilibrium by virtual work, stability and normal modes (notes II.A)."""

from __future__ import annotations

from fastapi import APIRouter

from app.derivations import on_scene
from app.schemas import EquilibriaRequest, EquilibriaResponse, Message, ValidationErrors

router = APIRouter(prefix="/api/v1", tags=["equilibria"])


def _equilibria(derivation, parameters: dict) -> dict:
    from mechanics.equilibria import equilibria

    return equilibria(derivation, parameters)


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
    return on_scene(request, _equilibria, request.parameters)
