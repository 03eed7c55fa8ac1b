"""``/api/v1/scenes``: the built-in scene catalog, for menus and as starting points to edit."""

from __future__ import annotations

from fastapi import APIRouter, HTTPException

from app.schemas import Message, SceneDetail, SceneSummary
from mechanics.scenes import list_scenes, load_scene

router = APIRouter(prefix="/api/v1/scenes", tags=["scenes"])


def unknown_scene(scene_id: str) -> HTTPException:
    """The 404 for a scene id that names no built-in scene (shared with /derive)."""
    return HTTPException(status_code=404, detail=f"unknown scene '{scene_id}'")


@router.get("", response_model=list[SceneSummary], summary="List the built-in scenes")
def get_scenes() -> list[dict]:
    """Every built-in scene in teaching order: id, title, one-line summary, coordinates."""
    return list_scenes()


@router.get(
    "/{scene_id}",
    response_model=SceneDetail,
    response_model_exclude_unset=True,
    responses={404: {"model": Message}},
    summary="One built-in scene's spec",
)
def get_scene(scene_id: str) -> SceneDetail:
    """The scene's spec as written in its file: edit it and POST it to /api/v1/derive."""
    try:
        spec = load_scene(scene_id)
    except KeyError:
        raise unknown_scene(scene_id) from None
    return SceneDetail.model_validate({"id": scene_id, "spec": spec})
