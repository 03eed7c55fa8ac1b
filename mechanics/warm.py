"""Built-in scenes made ready before the class asks for them.

A scene's first request pays for its derivation (up to ~2 s of sympy), its compiled right-hand
side (a C build) and its first equilibria (sympy's solve): a lecture hall that opens a scene at
the same moment would all wait for that. The server does it for every built-in scene when it
starts, in the background: `warm_in_process` in the server's own process (its simulations run
there), `warm_in_worker` in the pool worker that the scene's analysis requests go to (the pool
sends a scene to the same worker each time). Derivations land in the shared cache too, so a
restarted server or another machine finds them; compiled libraries land in this machine's disk
cache (each machine generates and compiles its own C). A cache that cannot write (a full disk, a
hung Redis) only makes warming slower, never fail.
"""

from __future__ import annotations

import time

from mechanics.derive import derivation_of_scene, derive_scene
from mechanics.equilibria import equilibria
from mechanics.jscode import scene_live_module
from mechanics.numeric import compiled_scene
from mechanics.simulate import SimulationRequest, simulate


def warm_in_process(scene_id: str) -> float:
    """The scene's derivation (JSON, through the cache), its compiled equations and their
    JavaScript, as the server's `/derive`, `/simulate` and `/live` use them. Returns the seconds
    it took."""
    start = time.perf_counter()
    derive_scene(scene_id)
    compiled_scene(scene_id)
    scene_live_module(scene_id)  # the page's live preview asks for it first of all
    # The page's own run: its constraint forces, energies and checks are built (lambdified) on a
    # scene's first run, up to 1.5 s of sympy that holds the GIL, so a class's first runs would
    # queue behind it. A short run builds them all.
    simulate(scene_id, None, SimulationRequest(t_end=0.5, fps=30, constraint_forces=True))
    return time.perf_counter() - start


def warm_in_worker(scene_id: str) -> float:
    """The derivation a pool worker judges answers against, and the equilibria at the scene's
    own parameters (which also derives, once, what every other parameter value reuses)."""
    start = time.perf_counter()
    d = derivation_of_scene(scene_id)
    d.solved_accelerations  # noqa: B018 — checking an answer for q̈ needs it; computed once
    equilibria(d, {})
    return time.perf_counter() - start
