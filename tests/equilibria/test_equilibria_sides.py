"""A spring along a line has two sides of its anchor, and the equilibria step derives each: the
cart on a wall spring with a pendulum under it rests at x = 0 and at x = −2ℓ₀ (the cart on the
far side of the anchor, the spring again at its rest length), the bob down or up at each.

What a play-test saw there once: the step showed the first side's conditions twice (with and
without its label), the note said "each was recognised in closed form" and "none was" of the
same system, θ = 0 read −1.5·10⁻³⁶, and x = −2 at M = 2, ℓ₀ = 1 was taken for −M and so left
as a bare number. Expected values are worked out here by hand: V, M and K of this system.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechanics.derive import derive_model
from mechanics.equilibria import equilibria

M, m, L, K, G, L0 = 2.0, 0.5, 0.8, 20.0, 9.81, 1.0


def cart_spring() -> dict:
    return {
        "title": "cart on a wall spring with a pendulum",
        "coordinates": ["x", "theta"],
        "parameters": {"M": M, "m": m, "l": L, "k": K, "g": G, "L0": L0},
        "points": [{"name": "wall", "position": [0, 0, 0]}],
        "bodies": [
            {"name": "cart", "mass": "M", "position": ["L0+x", 0, 0]},
            {
                "name": "bob",
                "mass": "m",
                "position": {
                    "frame": "N",
                    "components": ["l*sin(theta)", "-l*cos(theta)", 0],
                    "from": "cart",
                },
            },
        ],
        "springs": [{"a": "wall", "b": "cart", "k": "k", "rest_length": "L0"}],
        "gravity": {"acceleration": "g"},
        "initial": {"x": 0.1, "theta": 0.3},
    }


def by_hand(theta: float, rest: float = L0) -> tuple[bool, list[float]]:
    """Stable, and the frequencies: V = ½k(|L0 + x| − L0)² − mgl cos θ has K = diag(k, mgl cos θ)
    at either rest length of the spring; T gives M = [[M + m, ml cos θ], [ml cos θ, ml²]]."""
    mass = np.array([[M + m, m * L * math.cos(theta)], [m * L * math.cos(theta), m * L * L]])
    stiff = np.diag([K, m * G * L * math.cos(theta)])
    w2 = np.linalg.eigvals(np.linalg.solve(mass, stiff)).real
    return bool((w2 > 0).all()), sorted(math.sqrt(w) for w in w2 if w > 0)


@pytest.mark.parametrize("rest", [L0, 1.5])
def test_both_sides_of_the_anchor_each_bob_up_and_down(rest):
    result = equilibria(derive_model(cart_spring()), {"L0": rest})
    got = sorted((e["q"]["x"], e["q"]["theta"]) for e in result["equilibria"])
    # exactly 0 and π: the closed form's value, not the search's round-off
    assert got == [(-2 * rest, 0.0), (-2 * rest, math.pi), (0.0, 0.0), (0.0, math.pi)]
    for e in result["equilibria"]:
        stable, omegas = by_hand(e["q"]["theta"], rest)
        assert e["stable"] is stable, e
        if stable:
            assert e["frequencies"] == pytest.approx(omegas, rel=1e-9)
            # whose eigenvalues ±ωi are: the motion's, not K's (K's are real and positive)
            assert "the motion's eigenvalues" in e["reason"], e["reason"]
        # each is recognised: −2ℓ₀ is −2 L0 whatever else equals 2 (M = 2 at the defaults)
        assert e["symbolic"]["x"] == ("0" if e["q"]["x"] == 0 else "-2*L0"), e
        assert e["symbolic"]["theta"] in ("0", "pi")


def test_one_sentence_about_the_search_over_both_sides():
    warnings = equilibria(derive_model(cart_spring()), {})["warnings"]
    said = [w for w in warnings if "numeric search" in w]
    assert len(said) == 1, warnings
    assert "each was recognised in closed form" in said[0]


def test_the_step_shows_each_sides_conditions_once():
    (step, *_) = equilibria(derive_model(cart_spring()), {})["steps"]
    conditions = [p for p in step["plain"] if p.startswith("Q_")]
    assert len(conditions) == len(set(conditions)) == 4, step["plain"]
    # each names its side, and the far side's Q_x is −k (2ℓ₀ + x): ½k(−p − ℓ₀)² differentiated
    assert all("spring1: ℓ = " in p for p in conditions), conditions
    assert "Q_x = -k*(2*L0 + x) = 0 (spring1: ℓ = -L0 - x)" in conditions
    assert len(step["latex"]) == len(step["plain"]) == len(step["labels"])
