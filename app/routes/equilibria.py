"""``/api/v1/equilibria``: equilibrium by virtual work, stability and normal modes (notes II.A)."""

from __future__ import annotations

from fastapi import APIRouter, Request

from app.derivations import on_scene
from app.schemas import EquilibriaRequest, EquilibriaResponse, Message, ValidationErrors

router = APIRouter(prefix="/api/v1", tags=["equilibria"])


@router.post(
    "/equilibria",
    response_model=EquilibriaResponse,
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {"model": ValidationErrors, "description": "A field is invalid."},
        503: {"model": Message, "description": "The search ran past its time budget."},
    },
    summary="Equilibria, their stability and small oscillations",
)
def post_equilibria(request: EquilibriaRequest, http: Request) -> dict:
    """δW = Σ Q_j δq_j = 0 at rest, solved in closed form where sympy can (with the condition
    under which each root exists), numerically otherwise; each equilibrium linearized to
    M δq̈ + C δq̇ + K δq = 0 for its stability, frequencies and normal modes."""
    from mechanics.jobs import equilibria_json

    return on_scene(
        http, request, equilibria_json, request.parameters, what="searching for equilibria"
    )
