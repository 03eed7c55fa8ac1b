"""The derived equations of every built-in scene against sympy's own LagrangesMethod/KanesMethod.

The oracle takes the same bodies (as sympy Particle/RigidBody) but forms the Lagrangian, the
potential and the generalized forces its own way: V from the bodies' heights and the springs'
stretch written out here, non-conservative forces as a forcelist. Agreement is checked at random
states, relative to the size of the terms.
"""

from __future__ import annotations

import random

import pytest
import sympy as sp

from mechanics import oracle
from mechanics.derive import derivation_of_scene
from mechanics.model import T as t
from mechanics.scenes import scene_ids


def random_state(model, rng: random.Random) -> dict:
    values = {}
    for name, sym in model.params.items():
        default = model.spec.parameters[name]
        values[sym] = default * rng.uniform(0.7, 1.3) if default else rng.uniform(-1, 1)
    for name, q in zip(model.coordinate_names, model.q, strict=True):
        # Angles anywhere; lengths small and positive, so radii stay radii and no spring
        # passes through zero length (where |d| and the signed length part ways).
        angle = model.spec.units.get(name) == "rad"
        values[q] = rng.uniform(-3, 3) if angle else rng.uniform(0.1, 0.6)
    for qd in model.qd:
        values[qd] = rng.uniform(-2, 2)
    values[t] = rng.uniform(0, 5)
    return values


def numeric(matrix, model, values) -> list[float]:
    """Evaluate at a state; xreplace swaps whole q̇(t) nodes before the q(t) inside them."""
    subs = {k: sp.Float(v, 30) for k, v in values.items()}
    return [float(sp.N(e.xreplace(subs), 20)) for e in matrix]


def assert_close(ours, theirs, what):
    scale = max(1.0, *(abs(x) for x in theirs))
    for a, b in zip(ours, theirs, strict=True):
        assert abs(a - b) <= 1e-10 * scale, f"{what}: {ours} != {theirs}"


@pytest.mark.parametrize("scene_id", scene_ids())
def test_mass_matrix_and_forcing_match_lagranges_method(scene_id):
    d = derivation_of_scene(scene_id)
    model = d.model
    lm = oracle.lagranges_method(model)
    rng = random.Random(scene_id)
    for _ in range(20):
        values = random_state(model, rng)
        assert_close(
            numeric(d.work.mass_matrix, model, values),
            numeric(lm.mass_matrix, model, values),
            f"{scene_id} M",
        )
        assert_close(
            numeric(d.work.forcing, model, values),
            numeric(lm.forcing, model, values),
            f"{scene_id} f",
        )


@pytest.mark.parametrize("scene_id", ["double_pendulum", "cart_pendulum", "physical_pendulum"])
def test_accelerations_match_kanes_method(scene_id):
    """Kane's method shares nothing with Lagrange's but the bodies and the applied forces."""
    d = derivation_of_scene(scene_id)
    model = d.model
    M, f = oracle.kanes_method(model)
    n = len(model.q)
    rng = random.Random(scene_id)
    for _ in range(20):
        values = random_state(model, rng)
        theirs = sp.Matrix(n, n, numeric(M, model, values)).LUsolve(
            sp.Matrix(numeric(f, model, values))
        )
        ours = numeric(d.work.accelerations, model, values)
        assert_close(ours, [float(x) for x in theirs], f"{scene_id} q_ddot")
