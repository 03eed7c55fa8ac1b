"""Simplification has a size budget: past it the correct expanded form is kept, and flagged."""

from __future__ import annotations

import time

import sympy as sp

from mechanics.derive import derive_model

SPEC = {
    "title": "Particle in a polynomial well",
    "coordinates": ["x", "y"],
    "parameters": {"m": 1.0},
    "bodies": [{"name": "p", "mass": "m", "position": ["x", "y"]}],
    "potentials": [{"name": "well", "expression": "(x + y + 1)**16"}],
}


def test_oversized_pieces_are_kept_correct_and_flagged():
    start = time.perf_counter()
    d = derive_model(SPEC)
    assert time.perf_counter() - start < 20
    assert any("too large to simplify" in w for w in d.work.warnings)
    x, y = d.model.q
    m = d.model.params["m"]
    expected_fx = -16 * (x + y + 1) ** 15  # m ẍ = −∂V/∂x
    assert sp.expand(d.work.forcing[0] - expected_fx) == 0
    assert d.work.mass_matrix == sp.Matrix([[m, 0], [0, m]])


def test_small_scenes_carry_no_simplification_warning():
    d = derive_model(
        {
            "coordinates": ["x"],
            "parameters": {"m": 1.0, "k": 2.0},
            "bodies": [{"name": "p", "mass": "m", "position": ["x", 0]}],
            "potentials": [{"name": "spring", "expression": "k*x**2/2"}],
        }
    )
    assert d.work.warnings == []


def test_flags_do_not_depend_on_what_an_earlier_derivation_cached():
    """The simplifier's caches are shared by every derivation in a process: a second derivation
    of the same spec (every piece a cache hit) must flag exactly what the first one flagged."""
    first = derive_model(SPEC)
    second = derive_model(SPEC)
    assert any("too large to simplify" in w for w in first.work.warnings)
    assert second.work.warnings == first.work.warnings
    assert second.to_json()["equations"] == first.to_json()["equations"]
