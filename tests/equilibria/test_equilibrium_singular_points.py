"""Points where no coordinate carries inertia (∂r/∂q = 0, so M = 0 and every Q_j = 0 there
together) are judged in the configuration, never "stable because no coordinate carries inertia"
(issue 23, item 1; review round 4 of "no confident wrong word").

By hand: a bead on the cycloid x = a(s − sin s), y = ∓a(1 − cos s) has M = 2 m a²(1 − cos s),
zero at the cusp s = 0, where the wire is vertical (dr/ds ∝ (s²/2, ∓s)). With the arch hanging
down (y = −a(1 − cos s)) the cusp is the top: V = −m g a(1 − cos s) is largest there and gravity
pulls along the wire right up to it (Q/√M → √m g ≠ 0): a bead at rest slides off, no
equilibrium. With the arches standing up (y = +a(1 − cos s)) the cusp is a notch between two
arches, V lowest there: the bead sits in it. The bottom of a hanging arch (s = π) is a smooth
minimum: V'' = m g a, M = 4 m a², ω = √(g/(4a)) (the tautochrone's period 4π√(a/g)). A bead on
the line x = s³ has M = 9 m s⁴: on a spring to the origin V = k s⁶/2 (a minimum), on a hill
V = −k s⁶/2 (a maximum, unstable).
"""

from __future__ import annotations

import math

import pytest

from mechanics.derive import derive_model
from mechanics.equilibria import STABLE_KINDS, equilibria

G, A = 9.81, 1.0


def cycloid(hanging: bool) -> dict:
    sign = "-" if hanging else ""
    return {
        "title": "bead on a cycloid",
        "coordinates": ["s"],
        "parameters": {"m": 1.0, "a": A, "g": G},
        "bodies": [
            {
                "name": "bead",
                "mass": "m",
                "position": ["a*(s - sin(s))", f"{sign}a*(1 - cos(s))", 0],
            }
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }


def cubic_line(potential: str) -> dict:
    """A bead on the x axis parametrized by x = s³; ``potential``: 'spring' (to the origin,
    rest length 0: V = k s⁶/2) or 'hill' (V = −k s⁶/2)."""
    spec = {
        "title": "bead on x = s^3",
        "coordinates": ["s"],
        "parameters": {"m": 1.0, "k": 2.0},
        "bodies": [{"name": "bead", "mass": "m", "position": ["s**3", 0, 0]}],
    }
    if potential == "spring":
        spec["points"] = [{"name": "o", "position": [0, 0, 0]}]
        spec["springs"] = [{"name": "sp", "a": "o", "b": "bead", "k": "k", "rest_length": 0}]
    else:
        spec["potentials"] = [{"name": "hill", "expression": "-k*s**6/2"}]
    return spec


def near(out: dict, s: float) -> dict | None:
    return next((e for e in out["equilibria"] if abs(e["q"]["s"] - s) <= 1e-6), None)


def test_the_cusp_at_the_top_of_a_hanging_arch_is_never_stable():
    out = equilibria(derive_model(cycloid(hanging=True)))
    top = near(out, 0.0)
    assert top is None or top["kind"] not in STABLE_KINDS
    if top is None:  # left out: said why, in the configuration's terms
        assert any("s = 0" in w and "not an equilibrium" in w for w in out["warnings"])
    assert not any(
        "because no coordinate carries inertia" in e["reason"] for e in out["equilibria"]
    )


def test_the_bottom_of_a_hanging_arch_swings_with_the_tautochrone_frequency():
    out = equilibria(derive_model(cycloid(hanging=True)))
    bottom = near(out, math.pi)
    assert bottom["kind"] == "stable"
    assert bottom["frequencies"] == pytest.approx([math.sqrt(G / (4 * A))], rel=1e-9)


def test_a_cusp_between_two_standing_arches_is_a_notch_the_bead_rests_in():
    out = equilibria(derive_model(cycloid(hanging=False)))
    notch = near(out, 0.0)
    assert notch is not None and notch["kind"] == "stable" and notch["stable"] is True
    assert "rises on both sides" in notch["reason"]
    assert near(out, math.pi)["kind"] == "unstable"  # the top of a standing arch


def test_a_stationary_parametrization_at_a_minimum_is_stable_by_the_potential():
    out = equilibria(derive_model(cubic_line("spring")))
    e = near(out, 0.0)
    assert e["kind"] == "stable" and "rises on both sides" in e["reason"]
    assert "singular" in e["reason"]


def test_a_stationary_parametrization_at_a_maximum_is_not_stable():
    out = equilibria(derive_model(cubic_line("hill")))
    e = near(out, 0.0)
    assert e is None or (e["kind"] not in STABLE_KINDS and e["stable"] is False)
