"""Stability does not depend on the units: a verdict is the same for a mass of 1e-13 kg or
1e13 kg, a length of 1e-7 m or 1 m (hostile play-test: absolute tolerances made a tiny mass
'no inertia, stable' for the inverted pendulum, and a small K 'singular, cannot decide').
Expectations by hand: a pendulum's bottom is stable with ω = √(g/l), its top unstable with
λ = √(g/l); a bead on a hoop spinning at Ω² > g/R is stable off the axis at cos θ = g/(Ω²R)
with ω = Ω sin θ.
"""

from __future__ import annotations

import math

import pytest

from mechanics.derive import derivation_of_scene
from mechanics.equilibria import equilibria


def _by_angle(out: dict, name: str = "theta") -> dict[float, dict]:
    return {round(e["q"][name], 6): e for e in out["equilibria"]}


@pytest.mark.parametrize("m", [1e-13, 1e-10, 1.0, 1e13])
@pytest.mark.parametrize("length", [1e-7, 1.0, 1e5])
def test_the_pendulums_verdicts_do_not_depend_on_mass_or_length(m, length):
    g = 9.81
    out = equilibria(derivation_of_scene("simple_pendulum"), {"m": m, "l": length, "g": g})
    eq = _by_angle(out)
    bottom, top = eq[0.0], eq[round(math.pi, 6)]
    assert bottom["kind"] == "stable"
    assert bottom["frequencies"] == [pytest.approx(math.sqrt(g / length), rel=1e-6)]
    assert top["kind"] == "unstable"
    growth = max(re for re, _ in top["eigenvalues"])
    assert growth == pytest.approx(math.sqrt(g / length), rel=1e-6)


@pytest.mark.parametrize("m", [1e-12, 1.0, 1e12])
def test_the_hoops_off_axis_equilibria_do_not_depend_on_the_beads_mass(m):
    R, omega, g = 0.5, 6.0, 9.81
    out = equilibria(derivation_of_scene("bead_on_hoop"), {"m": m, "R": R, "Omega": omega, "g": g})
    theta = math.acos(g / (omega**2 * R))
    eq = _by_angle(out)
    for side in (theta, -theta):
        e = eq[round(side, 6)]
        assert e["kind"] == "stable"
        assert e["frequencies"] == [pytest.approx(omega * math.sin(theta), rel=1e-6)]
    assert eq[0.0]["kind"] == "unstable"


def test_a_light_lower_bob_still_gives_the_double_pendulums_two_modes():
    """m2 → 0: the upper bob swings as a simple pendulum, the light lower one as a pendulum of
    length l2 hanging from it; with l1 = l2 = l both frequencies tend to √(g/l)."""
    out = equilibria(derivation_of_scene("double_pendulum"), {"m2": 1e-9})
    bottom = next(e for e in out["equilibria"] if max(abs(v) for v in e["q"].values()) < 1e-9)
    assert bottom["kind"] == "stable"
    w = math.sqrt(9.81 / 1.0)
    assert sorted(bottom["frequencies"]) == [pytest.approx(w, rel=1e-3)] * 2


def test_a_spinning_hoops_verdicts_speak_of_the_effective_potential():
    """The bead's V = −mgR cos θ has V''(0) = mgR > 0, a minimum, yet θ = 0 is unstable at
    Ω² > g/R: what has no minimum there is V_eff = V − ½ m R² Ω² sin²θ, with
    V_eff''(0) = mR(g − Ω²R) < 0. Saying 'the potential has no minimum' contradicted the V
    the page shows (student play-test)."""
    m, R, omega, g = 0.1, 0.5, 6.0, 9.81
    assert m * g * R > 0 and m * R * (g - omega**2 * R) < 0  # the premise, by hand
    out = equilibria(derivation_of_scene("bead_on_hoop"), {})
    for e in out["equilibria"]:
        assert "effective potential" in e["reason"], e["reason"]
    for e in equilibria(derivation_of_scene("simple_pendulum"), {})["equilibria"]:
        assert "effective" not in e["reason"]  # nothing turns: V itself
