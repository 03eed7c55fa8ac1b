"""Built-in scenes are made ready when the server starts (app/derivations.py warm_up)."""

from __future__ import annotations

import threading

import pytest

from app import derivations
from mechanics.derive import derivation_of_scene
from mechanics.numeric import compiled_scene
from mechanics.pool import WorkerPool


@pytest.fixture
def pool():
    p = WorkerPool(size=1, per_client=1).start()
    yield p
    p.close()


def test_warm_up_derives_and_compiles_every_scene_once(pool, monkeypatch):
    scenes = ["simple_pendulum", "spring_mass_damper"]
    monkeypatch.setattr(derivations, "scene_ids", lambda: scenes)
    derivation_of_scene.cache_clear()
    compiled_scene.cache_clear()  # earlier tests may have compiled them in this process
    derivations.warm_up(pool, threading.Event())
    assert derivations.warm_state["done"] == derivations.warm_state["of"] == 2
    assert derivations.warm_state["seconds"] is not None
    assert derivation_of_scene.cache_info().currsize >= 2
    hits, misses = compiled_scene.cache_info().hits, compiled_scene.cache_info().misses
    for scene_id in scenes:  # already there: a lookup, not a derivation and a compilation
        assert compiled_scene(scene_id).n >= 1
    assert compiled_scene.cache_info().hits == hits + 2
    assert compiled_scene.cache_info().misses == misses


def test_a_stopped_server_stops_warming(pool, monkeypatch):
    monkeypatch.setattr(derivations, "scene_ids", lambda: ["simple_pendulum"] * 5)
    stop = threading.Event()
    stop.set()
    derivations.warm_up(pool, stop)
    assert derivations.warm_state["done"] == 0 and derivations.warm_state["seconds"] is None


def test_warming_is_on_unless_switched_off(monkeypatch):
    from app.settings import Settings

    assert Settings.from_env({}).warm is True
    assert Settings.from_env({"LAGRANGE_LAB_WARM": "0"}).warm is False


def test_after_warming_the_pages_first_run_builds_nothing(monkeypatch):
    """The page's run asks for constraint forces, which Newton's method and lambdify build on a
    scene's first run (1.5 s of GIL-holding sympy for the double pendulum): a class's first runs
    queued behind it, to a simulate p95 of 2.5 s under load. Warming builds them."""
    import sympy as sp

    from mechanics import warm
    from mechanics.simulate import SimulationRequest, simulate

    compiled_scene.cache_clear()
    warm.warm_in_process("double_pendulum")
    built = []
    real = sp.lambdify
    monkeypatch.setattr(sp, "lambdify", lambda *a, **k: built.append(a) or real(*a, **k))
    page_run = SimulationRequest(t_end=10, fps=30, method="dop853_c", constraint_forces=True)
    result = simulate("double_pendulum", None, page_run)
    assert result["constraint_forces"]  # the run did ask for them
    assert built == []
