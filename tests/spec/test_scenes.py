"""The built-in scene catalog: every file loads, validates, declares its units, and the loader
never turns user text into a path. Physics oracles for these scenes live with the engine's tests."""

from __future__ import annotations

import re
from importlib import resources

import pytest

from mechanics import scenes
from mechanics.scenes import list_scenes, load_scene, scene_ids
from mechanics.spec import RESERVED, parse_spec

ALL_IDS = scene_ids()
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def expressions(spec: dict) -> list[tuple[str, object, bool]]:
    """(field, expression, velocities allowed?) for every expression a scene contains."""
    out: list[tuple[str, object, bool]] = []

    def position(field: str, pos: object, velocities: bool = False) -> None:
        comps = pos["components"] if isinstance(pos, dict) else pos
        out.extend((f"{field}[{i}]", c, velocities) for i, c in enumerate(comps))

    for i, f in enumerate(spec.get("frames", [])):
        out.append((f"frames[{i}].angle", f["angle"], False))
    for i, p in enumerate(spec.get("points", [])):
        position(f"points[{i}].position", p["position"])
    for i, b in enumerate(spec["bodies"]):
        out.append((f"bodies[{i}].mass", b["mass"], False))
        position(f"bodies[{i}].position", b["position"])
        for key, value in b.get("inertia", {}).items():
            out.append((f"bodies[{i}].inertia.{key}", value, False))
    if "gravity" in spec:
        out.append(("gravity.acceleration", spec["gravity"]["acceleration"], False))
    for group, keys in (("springs", ("k", "rest_length")), ("dampers", ("c",))):
        for i, s in enumerate(spec.get(group, [])):
            out.extend((f"{group}[{i}].{k}", s[k], False) for k in keys if k in s)
    for group in ("forces", "torques"):
        for i, f in enumerate(spec.get(group, [])):
            position(f"{group}[{i}].vector", f["vector"], velocities=True)
    for i, p in enumerate(spec.get("potentials", [])):
        out.append((f"potentials[{i}].expression", p["expression"], False))
    return out


def test_catalog_has_at_least_thirteen_scenes() -> None:
    assert len(ALL_IDS) >= 13
    assert "simple_pendulum" in ALL_IDS


def test_ids_are_unique_snake_case_and_match_the_files() -> None:
    files = [
        entry.name
        for entry in resources.files("mechanics.scenes").iterdir()
        if entry.name.endswith(".toml")
    ]
    assert sorted(name.removesuffix(".toml") for name in files) == ALL_IDS
    assert len(set(ALL_IDS)) == len(ALL_IDS)
    assert all(re.fullmatch(r"[a-z][a-z0-9]*(_[a-z0-9]+)*", i) for i in ALL_IDS)


@pytest.mark.parametrize("scene_id", ALL_IDS)
def test_scene_passes_parse_spec(scene_id: str) -> None:
    spec = parse_spec(load_scene(scene_id))  # raises SpecError with field paths on failure
    assert spec.title and spec.title != "Untitled system"
    assert spec.summary and "\n" not in spec.summary


@pytest.mark.parametrize("scene_id", ALL_IDS)
def test_every_parameter_and_coordinate_has_a_unit(scene_id: str) -> None:
    raw = load_scene(scene_id)
    declared = set(raw["coordinates"]) | set(raw.get("parameters", {}))
    units = raw.get("units", {})
    assert declared - set(units) == set(), "missing units"
    assert all(isinstance(u, str) and u.strip() for u in units.values())
    assert all(units[q] in ("rad", "m") for q in raw["coordinates"])


@pytest.mark.parametrize("scene_id", ALL_IDS)
def test_expressions_use_only_declared_names(scene_id: str) -> None:
    raw = load_scene(scene_id)
    known = set(raw["coordinates"]) | set(raw.get("parameters", {})) | RESERVED
    velocities = {f"{q}_dot" for q in raw["coordinates"]}
    for field, expr, allow_dot in expressions(raw):
        if not isinstance(expr, str):
            continue
        for name in NAME.findall(expr):
            ok = name in known or (allow_dot and name in velocities)
            assert ok, f"{scene_id}: {field}: unknown name '{name}'"


@pytest.mark.parametrize("scene_id", ALL_IDS)
def test_initial_state_names_real_coordinates(scene_id: str) -> None:
    raw = load_scene(scene_id)
    qs = raw["coordinates"]
    assert set(raw.get("initial", {})) <= set(qs) | {f"{q}_dot" for q in qs}


def test_unknown_id_raises_key_error() -> None:
    with pytest.raises(KeyError):
        load_scene("no_such_scene")


@pytest.mark.parametrize(
    "bad", ["../etc/passwd", "/etc/passwd", "simple_pendulum.toml", "__init__", "", "..", 3]
)
def test_path_like_or_odd_ids_raise_key_error(bad: object) -> None:
    with pytest.raises(KeyError):
        load_scene(bad)  # type: ignore[arg-type]


def test_load_scene_returns_a_copy_callers_may_mutate() -> None:
    first = load_scene("simple_pendulum")
    first["parameters"]["l"] = 99.0
    first["bodies"].clear()
    again = load_scene("simple_pendulum")
    assert again["parameters"]["l"] == 1.0
    assert again["bodies"]


def test_list_scenes_is_the_whole_catalog_in_teaching_order() -> None:
    menu = list_scenes()
    assert menu[0]["id"] == "simple_pendulum"
    assert sorted(entry["id"] for entry in menu) == ALL_IDS
    assert set(scenes.TEACHING_ORDER) <= set(ALL_IDS)
    assert len(set(scenes.TEACHING_ORDER)) == len(scenes.TEACHING_ORDER)
    for entry in menu:
        assert set(entry) == {"id", "title", "summary", "coordinates"}
        assert entry["coordinates"] == load_scene(entry["id"])["coordinates"]


def test_has_a_three_dimensional_scene() -> None:
    raw = load_scene("particle_in_cone")
    assert any(f["axis"] != "z" for f in raw["frames"])
