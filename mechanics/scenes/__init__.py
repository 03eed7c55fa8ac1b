"""The built-in scene catalog: one small TOML spec per scene, shipped inside this package.

A scene is data (see STYLE.md, "A scene is data"): the same document a course tool would POST,
so adding a scene means adding one ``<id>.toml`` file here and nothing else. The loader only ever
opens files it found by listing this package, so a scene id from a URL is looked up, never joined
into a path.
"""

from __future__ import annotations

import copy
import tomllib
from functools import lru_cache
from importlib import resources
from importlib.resources.abc import Traversable
from typing import Any

#: Teaching order for menus: one coordinate before two, particles before rigid bodies, then the
#: time-dependent constraint and the 3-D scenes. A scene file missing here is listed after these,
#: alphabetically, so a new file shows up without touching this module.
TEACHING_ORDER: tuple[str, ...] = (
    "simple_pendulum",
    "spring_mass_damper",
    "atwood_machine",
    "incline_friction",
    "physical_pendulum",
    "rolling_disk",
    "coupled_oscillators",
    "elastic_pendulum",
    "cart_pendulum",
    "double_pendulum",
    "central_force",
    "bead_on_hoop",
    "spherical_pendulum",
    "particle_in_cone",
)

_SUFFIX = ".toml"


@lru_cache(maxsize=1)
def _scene_files() -> dict[str, Traversable]:
    """Scene id -> its file, found by listing the package (works from a wheel or a zip too)."""
    package = resources.files(__name__)
    return {
        entry.name.removesuffix(_SUFFIX): entry
        for entry in package.iterdir()
        if entry.name.endswith(_SUFFIX) and entry.is_file()
    }


@lru_cache(maxsize=64)  # keys are known scene ids only
def _parsed(scene_id: str) -> dict[str, Any]:
    return tomllib.loads(_scene_files()[scene_id].read_text(encoding="utf-8"))


def scene_ids() -> list[str]:
    """Every built-in scene id (the file stems), sorted."""
    return sorted(_scene_files())


def load_scene(scene_id: str) -> dict[str, Any]:
    """The raw spec dict of one scene, ready for ``parse_spec``; a fresh copy the caller may mutate.

    Raises KeyError(scene_id) for anything that is not a known id (including path-like text).
    """
    if not isinstance(scene_id, str) or scene_id not in _scene_files():
        raise KeyError(scene_id)
    return copy.deepcopy(_parsed(scene_id))


def list_scenes() -> list[dict[str, Any]]:
    """A menu entry per scene, in teaching order: id, title, summary and coordinate names."""
    known = _scene_files()
    ordered = [i for i in TEACHING_ORDER if i in known]
    ordered += sorted(set(known) - set(ordered))
    menu = []
    for scene_id in ordered:
        spec = _parsed(scene_id)
        menu.append(
            {
                "id": scene_id,
                "title": spec.get("title", scene_id),
                "summary": spec.get("summary", ""),
                "coordinates": list(spec.get("coordinates", [])),
            }
        )
    return menu
