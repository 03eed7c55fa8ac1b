"""Equilibria where no force acts along a coordinate: a family, told as one, neutral not stable.

With g = 0 a pendulum's Q_θ = −m g l sin θ vanishes for every θ: every angle is an equilibrium.
The numeric search used to sample that family into a score of 'marginal' points (and say sympy
had missed them); a spec without gravity was called 'stable' because 'K is positive definite'
when K = 0. The expectations come from the Lagrangians by hand.
"""

from __future__ import annotations

import json
import math

import pytest

from mechanics.derive import derivation_of_scene, derive_model
from mechanics.equilibria import equilibria
from mechanics.scenes import load_scene


def _eigen_imag(result: dict) -> list[float]:
    return sorted(abs(im) for _, im in result["eigenvalues"])


@pytest.mark.parametrize("scene_id", ["simple_pendulum", "double_pendulum"])
def test_without_gravity_every_configuration_is_one_neutral_family(scene_id):
    out = equilibria(derivation_of_scene(scene_id), {"g": 0.0})
    (only,) = out["equilibria"]
    d = derivation_of_scene(scene_id)
    assert only["free"] == d.model.coordinate_names  # every coordinate
    assert only["kind"] == "marginal" and only["stable"] is False
    assert "neutral" in only["reason"]
    assert any("every configuration is an equilibrium" in w for w in out["warnings"])
    assert not any("missed" in w for w in out["warnings"])


def test_a_spec_with_no_gravity_at_all_is_not_called_stable():
    """The pendulum with its gravity block removed: Q_θ is 0 as an expression (a free
    coordinate), so K = 0, which is not 'positive definite'."""
    spec = json.loads(json.dumps(load_scene("simple_pendulum")))
    del spec["gravity"]
    (only,) = equilibria(derive_model(spec), {})["equilibria"]
    assert only["free"] == ["theta"]
    assert only["kind"] == "marginal" and only["stable"] is False
    assert "neutral" in only["reason"] and "positive definite" not in only["reason"]


def test_the_elastic_pendulum_without_gravity_keeps_its_spring_and_frees_its_angle():
    """L = ½m(ṙ² + r²θ̇²) − ½k(r − l0)² with g = 0: r = l0 for every θ, and along r the
    spring gives ω² = k/m."""
    spec = load_scene("elastic_pendulum")
    p = spec["parameters"]
    out = equilibria(derivation_of_scene("elastic_pendulum"), {"g": 0.0})
    (only,) = out["equilibria"]
    assert only["q"]["r"] == pytest.approx(p["l0"], rel=1e-9)
    assert only["free"] == ["theta"]
    assert max(_eigen_imag(only)) == pytest.approx(math.sqrt(p["k"] / p["m"]), rel=1e-6)
    assert any("every value of theta is an equilibrium" in w for w in out["warnings"])


def test_the_spinning_hoop_without_gravity_has_its_centrifugal_equilibria():
    """V_eff = −½ m Ω² R² sin²θ when g = 0: maxima at 0 and π, minima at ±π/2 where
    ω = Ω (V_eff'' = m Ω² R², M = m R²). Nothing is free: the hoop's spin holds θ."""
    omega = load_scene("bead_on_hoop")["parameters"]["Omega"]
    out = equilibria(derivation_of_scene("bead_on_hoop"), {"g": 0.0})
    by_angle = {round(abs(e["q"]["theta"]), 6): e for e in out["equilibria"]}
    assert set(by_angle) == {0.0, round(math.pi / 2, 6), round(math.pi, 6)}
    assert by_angle[0.0]["kind"] == by_angle[round(math.pi, 6)]["kind"] == "unstable"
    side = by_angle[round(math.pi / 2, 6)]
    assert side["kind"] == "stable" and side["free"] == []
    assert max(_eigen_imag(side)) == pytest.approx(omega, rel=1e-6)
    assert not any("every" in w for w in out["warnings"])


def test_gravity_back_on_gives_the_usual_two():
    out = equilibria(derivation_of_scene("simple_pendulum"), {"g": 9.81})
    kinds = sorted((round(abs(e["q"]["theta"]), 6), e["kind"]) for e in out["equilibria"])
    assert kinds == [(0.0, "stable"), (round(math.pi, 6), "unstable")]
    assert all(e["free"] == [] for e in out["equilibria"])
