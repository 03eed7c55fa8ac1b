"""``/api/v1/newton``: Newton's method beside Lagrange's, and the constraint forces it reveals."""

from __future__ import annotations

from fastapi import APIRouter, Request

from app.derivations import on_scene
from app.schemas import DeriveRequest, Message, NewtonResponse, ValidationErrors

router = APIRouter(prefix="/api/v1", tags=["newton"])


@router.post(
    "/newton",
    response_model=NewtonResponse,
    responses={404: {"model": Message}, 422: {"model": ValidationErrors}, 503: {"model": Message}},
    summary="Newton's method and the constraint forces",
)
def post_newton(request: DeriveRequest, http: Request) -> dict:
    """Σ F = m a per body in its natural frame with the constraint force as an unknown,
    projected on the virtual displacements (the same equations as Lagrange's) and solved for
    the constraint forces: a pendulum's tension, a hoop's normal force, a string's tension."""
    from mechanics.jobs import newton

    return on_scene(http, request, newton, what="running Newton's method")
