"""``/api/v1/scenes``: the built-in scene catalog, for menus and as starting points to edit; the
catalog's drawings in one answer; and each scene's equations as a JavaScript module for the live
preview (mechanics/jscode.py)."""

from __future__ import annotations

import functools
import hashlib
import re
from collections.abc import Callable
from typing import Any

from fastapi import APIRouter, HTTPException, Request, Response
from pydantic import BaseModel, ConfigDict
from starlette.concurrency import run_in_threadpool

from app.schemas import Message, SceneDetail, SceneSpec, SceneSummary, ValidationErrors
from mechanics import cache
from mechanics.scenes import list_scenes, load_scene, scene_ids

router = APIRouter(prefix="/api/v1/scenes", tags=["scenes"])

#: A generated module under its content hash never changes: the browser keeps it for a year.
IMMUTABLE = "public, max-age=31536000, immutable"
#: What may change when the server is updated (the catalog, a module's current hash):
#: revalidated with its ETag on every visit, a 304 of a few hundred bytes when unchanged.
REVALIDATE = "no-cache"


def unknown_scene(scene_id: str) -> HTTPException:
    """The 404 for a scene id that names no built-in scene (shared with /derive)."""
    return HTTPException(status_code=404, detail=f"unknown scene '{scene_id}'")


@router.get("", response_model=list[SceneSummary], summary="List the built-in scenes")
def get_scenes() -> list[dict]:
    """Every built-in scene in teaching order: id, title, one-line summary, coordinates."""
    return list_scenes()


@router.get(
    "/catalog",
    summary="Every built-in scene with what its catalog drawing needs",
    responses={200: {"description": "id, title, spec and a 1-second run per scene"}},
)
async def get_catalog(request: Request) -> Response:
    """The catalog page draws every scene at its start with a faint line of its first second of
    motion: one answer carries each scene's spec and that short run (t, positions, frames), so the
    page makes one request instead of two per scene. Computed once per process."""
    body, etag = await run_in_threadpool(_catalog)
    return _cached(request, body, etag, "application/json", REVALIDATE)


@functools.lru_cache(maxsize=1)
def _catalog() -> tuple[bytes, str]:
    import orjson

    from mechanics.simulate import SimulationRequest, simulate

    entries: list[dict[str, Any]] = []
    for s in list_scenes():
        entry: dict[str, Any] = {**s, "spec": load_scene(s["id"])}
        try:
            run = simulate(
                s["id"], None, SimulationRequest(t_end=1.0, fps=30.0, check_sensitivity=False)
            )
            entry["run"] = {k: run[k] for k in ("t", "positions", "frames")}
        except Exception:  # noqa: BLE001 — one scene without a drawing must not blank the rest
            entry["run"] = None
        entries.append(entry)
    body = orjson.dumps(entries, option=orjson.OPT_SERIALIZE_NUMPY)
    return body, hashlib.sha256(body).hexdigest()[:16]


class LiveRequest(BaseModel):
    """A spec of your own, for its equations as JavaScript (the editor's live preview)."""

    model_config = ConfigDict(extra="forbid")
    scene: SceneSpec


#: Posted specs' modules by content hash, in the project's shared cache (mechanics/cache.py: the
#: disk every worker of a server reads, or Redis every server reads), so the GET that follows a
#: POST finds the module whichever worker it reaches (hostile play-test: with --workers 2 a
#: module kept in one worker's memory was a 404 in 7 of 12 GETs). An entry is verified on
#: read: its source must hash to the digest it is asked by.
LIVE_STORE = "live-module"
_DIGEST = re.compile(r"^[0-9a-f]{16}$")


def _module_of(digest: str) -> Callable[[Any], bool]:
    """The check of a stored module: a source whose hash is ``digest`` (jscode.LiveModule's)."""

    def check(value: Any) -> bool:
        source = value["source"]
        return hashlib.sha256(source.encode()).hexdigest()[:16] == digest

    return check


@router.post(
    "/live",
    responses={
        422: {"model": ValidationErrors, "description": "The scene is invalid."},
        503: {"model": Message, "description": "Past the time budget, or no JavaScript for it."},
    },
    summary="A posted scene's equations for the browser: the module's URL and slot names",
)
def post_live(request: LiveRequest, http: Request) -> Response:
    """Like ``GET /{scene_id}/live`` for a spec of your own: derived (and printed) in the
    worker pool under the derivation's time budget, the module kept here by its hash."""
    import orjson

    from app.derivations import in_pool, posted_key
    from mechanics.jscode import JsUnavailable, posted_live_json

    key = posted_key(request.scene)
    try:
        live = in_pool(
            http, posted_live_json, key, affinity=key, what="printing this scene's equations"
        )
    except JsUnavailable as exc:
        raise HTTPException(status_code=503, detail=f"no live preview: {exc}") from None
    source = live.pop("source")
    digest = live.pop("digest")
    cache.get_or_compute(
        LIVE_STORE, {"digest": digest}, lambda: {"source": source}, validate=_module_of(digest)
    )
    body = {"module": f"/api/v1/scenes/live/{digest}.js", **live}
    return Response(orjson.dumps(body), media_type="application/json")


@router.get(
    "/live/{digest}.js",
    responses={404: {"model": Message}},
    summary="A posted scene's equations as an ES module, by its content hash",
)
def get_posted_module(digest: str, request: Request) -> Response:
    """The module ``POST /live`` printed, immutable under its hash."""
    found = None
    if _DIGEST.match(digest):
        found = cache.get(LIVE_STORE, {"digest": digest}, validate=_module_of(digest))
    if found is None:
        raise HTTPException(
            status_code=404,
            detail=[
                {
                    "field": "digest",
                    "message": f"no module '{digest[:80]}' here (this server keeps a posted "
                    "scene's module a while after POST /api/v1/scenes/live): post the scene again",
                }
            ],
        )
    return _cached(request, found["source"].encode(), digest, "text/javascript", IMMUTABLE)


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


@router.get(
    "/{scene_id}/live",
    responses={404: {"model": Message}, 503: {"model": Message}},
    summary="The scene's equations for the browser: the module's URL and its slots' names",
)
async def get_live(scene_id: str, request: Request) -> Response:
    """Where the scene's generated JavaScript module is (a URL carrying its content hash, cached
    for a year) and the names of its slots in order: coordinates (y = [q, q̇, W_NC…]),
    parameters (p), the points ``places`` fills and the frames ``axes`` fills. The page steps
    these equations itself for a live preview while a slider moves; the server's run stays the
    measured one."""
    live = await _live(scene_id)
    body = {
        "module": f"/api/v1/scenes/{scene_id}/live.js?v={live.digest}",
        **live.slots(),
    }
    import orjson

    return _cached(request, orjson.dumps(body), live.digest, "application/json", REVALIDATE)


@router.get(
    "/{scene_id}/live.js",
    responses={404: {"model": Message}, 503: {"model": Message}},
    summary="The scene's equations as an ES module (rhs, places, axes, energy over slots)",
)
async def get_live_module(scene_id: str, request: Request, v: str = "") -> Response:
    """The module itself, ``text/javascript`` so a page imports it under its CSP ('self')
    without eval. Asked for with its current hash (``?v=``, from ``/live``) it is immutable."""
    live = await _live(scene_id)
    policy = IMMUTABLE if v == live.digest else REVALIDATE
    return _cached(request, live.source.encode(), live.digest, "text/javascript", policy)


async def _live(scene_id: str):
    if scene_id not in scene_ids():
        raise unknown_scene(scene_id)
    from mechanics.jscode import JsUnavailable, scene_live_module

    try:
        return await run_in_threadpool(scene_live_module, scene_id)
    except JsUnavailable as exc:
        raise HTTPException(status_code=503, detail=f"no live preview: {exc}") from None


def _cached(request: Request, body: bytes, etag: str, media_type: str, policy: str) -> Response:
    """``body`` with its ETag and caching policy, or a 304 when the client already has it."""
    tag = f'"{etag}"'
    headers = {"ETag": tag, "Cache-Control": policy}
    seen = [
        t.strip().removeprefix("W/") for t in request.headers.get("if-none-match", "").split(",")
    ]
    if tag in seen or "*" in seen:  # '*' matches any current version (RFC 9110 13.1.2)
        return Response(status_code=304, headers=headers)
    return Response(body, media_type=media_type, headers=headers)
