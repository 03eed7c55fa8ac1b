"""``/api/v1/derive``: the step-by-step Lagrangian derivation of a scene."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response

from app import derivations
from app.routes.scenes import unknown_scene
from app.schemas import DeriveRequest, DeriveResponse, Message, ValidationErrors

router = APIRouter(prefix="/api/v1", tags=["derive"])


@router.post(
    "/derive",
    response_model=DeriveResponse,  # documents the body; the route sends it pre-serialised
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {"model": ValidationErrors, "description": "The request or the scene is invalid."},
        503: {"model": Message, "description": "The derivation ran past its time budget."},
    },
    summary="Derive the equations of motion",
)
def post_derive(request: DeriveRequest, http: Request) -> Response:
    """Kinematics, energies, generalized forces, Lagrange's equations, the mass-matrix form and
    the conserved quantities, each as a step with prose, LaTeX and plain text.

    A built-in `scene_id` is answered from memory once derived; a posted `scene` is derived afresh
    under a time budget (20 s by default), so keep it small.
    """
    if request.scene_id is not None:
        body = derivations.scene_json(request.scene_id)
        if body is None:
            raise unknown_scene(request.scene_id)
    else:
        body = derivations.posted_json(http, request.scene)
    return Response(content=body, media_type="application/json")
