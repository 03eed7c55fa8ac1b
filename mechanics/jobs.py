"""The work a pool worker does for the web layer: one function per kind, JSON-ready results.

Each takes the scene as a *source*: a built-in scene's id, or a posted spec as canonical JSON text
(``spec_key``), so equal specs are equal keys. A worker keeps the derivations it computed
(`derivation_of`), and the pool sends equal keys to the same worker, so a posted spec is derived
once and its next check, equilibria or newton request reuses it; a simulation reuses the compiled
scene the same way (mechanics/numeric.py). Every function is a pure function of its arguments:
this is where results could be cached across workers and servers.

The pool preloads this module in its forkserver: every worker starts with sympy and the engine
imported.
"""

from __future__ import annotations

import json
from typing import Any

from mechanics.check import check
from mechanics.derive import Derivation, derivation_of_scene, derivation_of_spec, spec_text
from mechanics.equilibria import equilibria
from mechanics.newton import newton_json
from mechanics.predict import predict
from mechanics.simulate import SimulationRequest, simulate


def spec_key(document: dict) -> str:
    """A posted spec's canonical JSON: its cache key and its affinity in the pool."""
    return spec_text(document)


def posted_derivation(key: str) -> Derivation:
    """The sympy-level derivation of a posted spec, once per worker (shared with its compiled
    simulation: mechanics/numeric.py asks the same cache)."""
    return derivation_of_spec(key)


def derivation_of(scene_id: str | None, key: str | None) -> Derivation:
    """The derivation of a built-in scene (by id) or of a posted spec (by its key)."""
    return derivation_of_scene(scene_id) if scene_id is not None else posted_derivation(key)


def derivation_json(key: str) -> dict[str, Any]:
    """POST /derive of a posted spec."""
    return posted_derivation(key).to_json()


def answer_check(
    scene_id: str | None,
    key: str | None,
    quantity: str,
    answer: str,
    coordinate: str | None,
    reveal: bool,
) -> dict[str, Any]:
    """POST /check: a student's answer judged against the scene's derivation."""
    return check(derivation_of(scene_id, key), quantity, answer, coordinate).to_json(reveal)


def answer_predict(
    scene_id: str | None,
    key: str | None,
    quantity: str,
    answer: str,
    coordinate: str | None,
    parameters: dict[str, float],
    initial: dict[str, float],
    t_end: float,
) -> dict[str, Any]:
    """POST /check/predict: the answer's motion integrated beside the true one."""
    return predict(
        derivation_of(scene_id, key),
        quantity,
        answer,
        coordinate,
        parameters=parameters,
        initial=initial,
        t_end=t_end,
    )


def equilibria_json(
    scene_id: str | None, key: str | None, parameters: dict[str, float]
) -> dict[str, Any]:
    """POST /equilibria."""
    return equilibria(derivation_of(scene_id, key), parameters)


def newton(scene_id: str | None, key: str | None) -> dict[str, Any]:
    """POST /newton."""
    return newton_json(derivation_of(scene_id, key))


def simulation(key: str, options: SimulationRequest) -> dict[str, Any]:
    """POST /simulate of a posted spec (a built-in scene's runs in the server: trusted, cached)."""
    return simulate(scene=json.loads(key), request=options)
