"""Runs the derivation steps in order; caching lives here, nowhere else.

Two caches, because the two users differ: the JSON of a derivation goes through the ``derivation``
store of mechanics/cache.py (memory, then the disk or Redis: a restarted server, another worker or
another machine answers at once), keyed by the canonical spec (`derivation_key`); the sympy objects
a simulation compiles from are kept in memory per process.
"""

from __future__ import annotations

import functools
import json
import time
from dataclasses import dataclass
from typing import Any

from mechanics import cache
from mechanics.degenerate import check_mass_matrix
from mechanics.expr import to_latex, to_plain
from mechanics.model import Model, build_model
from mechanics.provenance import provenance_json
from mechanics.scenes import load_scene
from mechanics.spec import SceneSpec, parse_spec
from mechanics.steps import Step, Work, unsimplified
from mechanics.steps.conserved import conserved_quantities
from mechanics.steps.coords import generalized_coordinates
from mechanics.steps.energy import energies
from mechanics.steps.fbd import free_body_diagram
from mechanics.steps.forces import generalized_forces
from mechanics.steps.kinematics import kinematics
from mechanics.steps.lagrange import lagrange_equations
from mechanics.steps.matrix_form import mass_matrix_form

#: Bump (in mechanics/cache.py) when the derivation's output changes: it is part of every key.
ENGINE_VERSION = cache.ENGINE_VERSION

STEPS = (
    free_body_diagram,
    generalized_coordinates,
    kinematics,
    energies,
    generalized_forces,
    lagrange_equations,
    mass_matrix_form,
    conserved_quantities,
)


@dataclass
class Derivation:
    """The model, every quantity the steps derived, and the steps as shown."""

    model: Model
    work: Work
    steps: list[Step]
    seconds: float

    @functools.cached_property
    def solved_accelerations(self) -> list[Any]:
        """q̈: the simplified symbolic solution where the derivation has one, else M⁻¹f
        (n > 3, or M and f past the size budget). Checking answers and Newton's method need it."""
        w = self.work
        if w.accelerations is not None:
            return list(w.accelerations)
        return list(w.mass_matrix.LUsolve(w.forcing))

    def equations(self, fmt: Any) -> dict[str, Any]:
        """The results in one format (to_plain or to_latex), keyed as the API documents."""
        m, w = self.model, self.work
        names = m.coordinate_names
        eom = {n: f"{fmt(lhs)} = {fmt(Q)}" for n, lhs, Q in zip(names, w.eom_lhs, w.Q, strict=True)}
        return {
            "T": fmt(w.T),
            "V": fmt(w.V),
            "L": fmt(w.L),
            "generalized_forces": {n: fmt(Q) for n, Q in zip(names, w.Q, strict=True)},
            "eom": eom,
            "mass_matrix": [[fmt(e) for e in row] for row in w.mass_matrix.tolist()],
            "forcing": [fmt(e) for e in w.forcing],
            "accelerations": None
            if w.accelerations is None
            else {n: fmt(a) for n, a in zip(names, w.accelerations, strict=True)},
            "conserved": [
                {"name": c["name"], "coordinate": c["coordinate"], "expression": fmt(c["expr"])}
                for c in w.conserved
            ],
        }

    def to_json(self) -> dict[str, Any]:
        return {
            "scene": self.model.spec.model_dump(mode="json", by_alias=True, exclude_defaults=True),
            "steps": [s.to_json() for s in self.steps],
            "equations": self.equations(to_plain),
            "latex": self.equations(to_latex),
            "warnings": list(self.work.warnings),
            "seconds": round(self.seconds, 4),
            "provenance": provenance_json(self),
        }


def derive_model(spec: SceneSpec | dict, branches: dict[int, int] | None = None) -> Derivation:
    """Build the model and run every step; raises SpecError/ExprError for bad input.

    ``branches`` picks the side of its anchor each spring along a line is derived on (see
    `build_model`); simulations of a state on the other side ask for that variant.
    """
    start = time.perf_counter()
    model = build_model(spec, branches)
    work = Work()
    token = unsimplified.set([])
    try:
        steps = [step(model, work) for step in STEPS]
        if unsimplified.get():
            work.warnings.append(
                f"{len(unsimplified.get())} piece(s) were too large to simplify within the budget "
                "and are shown expanded: correct, but longer than a textbook would print."
            )
    finally:
        unsimplified.reset(token)
    derivation = Derivation(model, work, steps, time.perf_counter() - start)
    check_mass_matrix(derivation)
    return derivation


def derive(spec: SceneSpec | dict) -> dict[str, Any]:
    """The JSON derivation of any spec (a posted one: the caller runs this under a budget)."""
    return derive_model(spec).to_json()


@functools.lru_cache(maxsize=64)
def derivation_of_scene(scene_id: str, branches: tuple[tuple[int, int], ...] = ()) -> Derivation:
    """The sympy-level derivation of a built-in scene, once per process (and branch variant)."""
    return derive_model(parse_spec(load_scene(scene_id)), dict(branches) or None)


def spec_text(document: dict) -> str:
    """A posted spec as canonical JSON text: equal specs, equal keys (caches, pool affinity)."""
    return json.dumps(document, sort_keys=True, separators=(",", ":"))


@functools.lru_cache(maxsize=32)
def derivation_of_spec(text: str, branches: tuple[tuple[int, int], ...] = ()) -> Derivation:
    """The sympy-level derivation of a posted spec (by `spec_text`), once per process: its
    derive, check, equilibria and newton requests and its compiled simulation share it."""
    return derive_model(json.loads(text), dict(branches) or None)


def derivation_key(spec: SceneSpec | dict) -> dict[str, Any]:
    """What defines a derivation: the spec, validated and written canonically (defaults left out),
    so a posted copy of a built-in scene, or the same spec with its keys in another order or its
    defaults spelled out, is the same cache entry. Raises SpecError for a spec that does not
    parse."""
    spec = spec if isinstance(spec, SceneSpec) else parse_spec(spec)
    return {"spec": spec.model_dump(mode="json", by_alias=True, exclude_defaults=True)}


def derive_cached(spec: SceneSpec | dict, compute: Any = None) -> dict[str, Any]:
    """The JSON derivation of any spec through the ``derivation`` store: found, or computed once
    by ``compute()`` (default: `derive` here; the web layer passes its pool job) and shared."""
    return cache.get_or_compute(
        "derivation",
        derivation_key(spec),
        compute or (lambda: derive(spec)),
        validate=is_derivation_json,
    )


@functools.lru_cache(maxsize=128)
def scene_key(scene_id: str) -> dict[str, Any]:
    """`derivation_key` of a built-in scene, once per process (KeyError for an unknown one); the
    start of the key of any per-scene result (equilibria, newton, check). Do not change it."""
    return derivation_key(load_scene(scene_id))


def derive_scene(scene_id: str) -> dict[str, Any]:
    """A built-in scene's derivation, from the cache (memory, disk or Redis), else computed once
    and stored: the same entry as a posted copy of the scene."""
    return cache.get_or_compute(
        "derivation",
        scene_key(scene_id),
        lambda: derivation_of_scene(scene_id).to_json(),
        validate=is_derivation_json,
    )


def is_derivation_json(value: Any) -> bool:
    """Has ``value`` the shape of ``Derivation.to_json()``? (a disk entry is checked before it is
    served: one of another shape is recomputed, never passed on to the API)."""
    if not isinstance(value, dict) or not _DERIVATION_KEYS <= set(value):
        return False
    steps, warnings = value["steps"], value["warnings"]
    if not (isinstance(steps, list) and steps and isinstance(warnings, list)):
        return False
    if not all(isinstance(s, dict) and isinstance(s.get("id"), str) for s in steps):
        return False
    if not isinstance(value["scene"], dict):
        return False
    for equations in (value["equations"], value["latex"]):
        if not isinstance(equations, dict) or not _EQUATION_KEYS <= set(equations):
            return False
        n = len(equations["eom"]) if isinstance(equations["eom"], dict) else -1
        matrix, forcing = equations["mass_matrix"], equations["forcing"]
        if n < 1 or not (isinstance(matrix, list) and len(matrix) == n):
            return False
        if not all(isinstance(row, list) and len(row) == n for row in matrix):
            return False
        if not (isinstance(forcing, list) and len(forcing) == n):
            return False
        acc = equations["accelerations"]
        if acc is not None and not (isinstance(acc, dict) and len(acc) == n):
            return False
    return True


_DERIVATION_KEYS = frozenset({"scene", "steps", "equations", "latex", "warnings", "seconds"})
_EQUATION_KEYS = frozenset(
    {"T", "V", "L", "generalized_forces", "eom", "mass_matrix", "forcing", "accelerations"}
    | {"conserved"}
)
