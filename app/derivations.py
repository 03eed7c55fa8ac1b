"""The web layer's two ways into the engine's derivation, as ready-to-send JSON bytes.

A built-in scene is trusted and the same for everyone: its response is serialised once per process
and then served from a dict, so a warm request costs a lookup (the engine's own cache would still
make FastAPI re-validate and re-encode a large response every time). A posted scene is untrusted
work: it runs in a child process under a wall-time and memory budget.

``mechanics.derive`` is imported on first use, in the serving process (so forked children inherit
it): the app starts, answers /healthz, lists scenes and refuses bad specs without the derivation
steps loaded.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from typing import Any

from fastapi import HTTPException

from app.schemas import DeriveResponse
from mechanics.budget import run_with_budget
from mechanics.scenes import scene_ids
from mechanics.spec import SceneSpec, parse_spec

log = logging.getLogger(__name__)

DERIVE_SECONDS_ENV = "LAGRANGE_LAB_DERIVE_SECONDS"
DEFAULT_DERIVE_SECONDS = 20.0

_ready: dict[str, bytes] = {}


def derive_seconds() -> float:
    """The wall-time budget of one posted derivation: ``$LAGRANGE_LAB_DERIVE_SECONDS`` or 20 s."""
    raw = os.environ.get(DERIVE_SECONDS_ENV)
    if raw is None:
        return DEFAULT_DERIVE_SECONDS
    try:
        seconds = float(raw)
    except ValueError:
        seconds = -1.0
    if not 0 < seconds < float("inf"):
        log.warning("%s=%r is not a positive number of seconds; using 20", DERIVE_SECONDS_ENV, raw)
        return DEFAULT_DERIVE_SECONDS
    return seconds


def scene_json(scene_id: str) -> bytes | None:
    """The derivation of a built-in scene as JSON bytes, or None if there is no such scene."""
    body = _ready.get(scene_id)
    if body is None:
        if scene_id not in scene_ids():
            return None
        from mechanics.derive import derive_scene

        body = _ready[scene_id] = _encode(derive_scene(scene_id))
    return body


def posted_json(scene: SceneSpec) -> bytes:
    """The derivation of a posted scene as JSON bytes, computed under the time budget.

    The cross-field checks (names declared once, references that resolve) run here first: they are
    cheap, and a spec that fails them need not cost a process.
    """
    document = scene.model_dump(mode="json", by_alias=True, exclude_unset=True)
    parse_spec(document)
    from mechanics.derive import derive

    return _encode(run_with_budget(derive, document, seconds=derive_seconds()))


def _encode(result: dict[str, Any]) -> bytes:
    """Validate against the documented response once, when computed, and keep its JSON."""
    return DeriveResponse.model_validate(result).model_dump_json().encode()


def on_scene(request: Any, work: Callable[..., Any], *args: Any) -> Any:
    """``work(derivation, *args)`` for the scene a request names, the one way every analysis route
    reaches the engine: a built-in scene in this process (its derivation is cached), a posted one
    in a child process under the time and memory budget."""
    if request.scene_id is not None:
        if request.scene_id not in scene_ids():
            raise HTTPException(status_code=404, detail=f"unknown scene '{request.scene_id}'")
        from mechanics.derive import derivation_of_scene

        return work(derivation_of_scene(request.scene_id), *args)
    document = request.scene.model_dump(mode="json", by_alias=True, exclude_unset=True)
    parse_spec(document)
    return run_with_budget(_derive_then, document, work, *args, seconds=derive_seconds())


def _derive_then(document: dict, work: Callable[..., Any], *args: Any) -> Any:
    from mechanics.derive import derive_model

    return work(derive_model(document), *args)
