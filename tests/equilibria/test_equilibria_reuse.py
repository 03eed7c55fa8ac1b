"""Equilibria at new parameters reuse what was derived once per scene, and stay right.

A slider move asks for the equilibria at new numbers: the closed forms, the conditions' numeric
functions and the linearization are derived once per scene and only evaluated again. The answers
must be those of a fresh derivation, and those of the closed forms worked out by hand.
"""

from __future__ import annotations

import math

import pytest

from mechanics.derive import derive_model
from mechanics.equilibria import equilibria
from mechanics.scenes import load_scene
from mechanics.spec import SpecError


def _thetas(result: dict) -> list[float]:
    return sorted(round(e["q"]["theta"], 9) for e in result["equilibria"])


def test_bead_on_hoop_tracks_omega_like_the_closed_form():
    """θ = 0, π always; ±acos(g/(Ω²R)) only when Ω²R > g, and stable exactly then."""
    d = derive_model(load_scene("bead_on_hoop"))
    g, R = d.model.spec.parameters["g"], d.model.spec.parameters["R"]
    for omega in (1.0, 2.0, 4.0, 6.0, 9.0, 3.0, 1.5):
        r = equilibria(d, {"Omega": omega})
        expected = [0.0, math.pi]
        if omega**2 * R > g:
            a = math.acos(g / (omega**2 * R))
            expected += [a, -a]
        assert _thetas(r) == pytest.approx(sorted(expected), abs=1e-9), omega
        bottom = next(e for e in r["equilibria"] if abs(e["q"]["theta"]) < 1e-12)
        # at the bottom ω² = g/R − Ω²: stable while Ω² < g/R
        assert bottom["stable"] is (omega**2 < g / R)
        if bottom["stable"]:
            assert bottom["frequencies"] == pytest.approx([math.sqrt(g / R - omega**2)])


def test_a_scene_asked_again_answers_as_a_fresh_derivation():
    """The same parameters on a derivation that answered others first, and on a fresh one."""
    for scene, name in [("double_pendulum", "l2"), ("elastic_pendulum", "k")]:
        used = derive_model(load_scene(scene))
        base = used.model.spec.parameters[name]
        for factor in (0.5, 2.0, 1.3):
            equilibria(used, {name: base * factor})
        again = equilibria(used, {name: base * 0.7})
        fresh = equilibria(derive_model(load_scene(scene)), {name: base * 0.7})
        assert again["equilibria"] == fresh["equilibria"]
        assert again["warnings"] == fresh["warnings"]


def test_conditions_beyond_double_precision_are_refused_not_answered_none():
    """Ω = 1e308: Ω² overflows, so 0 · ∞ at θ = 0 says nothing; 'no equilibrium' would be
    a confident wrong answer (θ = 0 is one for every Ω)."""
    d = derive_model(load_scene("bead_on_hoop"))
    with pytest.raises(SpecError) as err:
        equilibria(d, {"Omega": 1e308})
    assert err.value.errors[0]["field"] == "parameters.Omega"
    assert "double precision" in err.value.errors[0]["message"]
