"""Equilibria the play-testers caught wrong: never a silent wrong answer, never a false alarm.

Every expectation is derived here by hand, independently of the engine: a zero-rest-length
spring's force −k d (so it hangs at m g/k below its anchor with ω = √(k/m) in every direction),
the Atwood machine's Q_x = (m₁ − m₂) g, the coupled oscillators' conditions with k = 0, the
spherical pendulum's small swings about the bottom in Cartesian form (x, z: ω = √(g/l) twice),
and the elastic pendulum's M and K at its rest point, whose first-order eigenvalues numpy gives.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from mechanics.derive import derivation_of_scene, derive_model
from mechanics.equilibria import equilibria
from mechanics.scenes import load_scene

M, K, G = 2.0, 10.0, 9.81


def hanging(coordinates: list[str]) -> dict:
    """A bob on a spring from the origin whose rest length is a parameter (set to 0 here), in
    one (y) or two (x, y) coordinates, gravity along −y."""
    position = ["x", "y", 0] if coordinates == ["x", "y"] else [0, "y", 0]
    return {
        "title": "Zero-length spring",
        "coordinates": coordinates,
        "parameters": {"m": M, "k": K, "l0": 0.0, "g": G},
        "bodies": [{"name": "bob", "mass": "m", "position": position}],
        "springs": [{"name": "s", "a": "O", "b": "bob", "k": "k", "rest_length": "l0"}],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }


def only(result: dict) -> dict:
    assert len(result["equilibria"]) == 1, [e["q"] for e in result["equilibria"]]
    return result["equilibria"][0]


# --- 1. a spring of rest length 0 -----------------------------------------------------------


@pytest.mark.parametrize("coordinates", [["y"], ["x", "y"]])
@pytest.mark.parametrize("g", [G, 0.0])
def test_a_zero_rest_length_spring_hangs_m_g_over_k_below_its_anchor(coordinates, g):
    """F = −k d − m g ŷ = 0 at d = (0, −m g/k): at the anchor itself when g = 0 (where ℓ = 0,
    the 0/0 of its direction vector that called this 'no equilibrium'). V = ½k|d|² + m g y is
    isotropic: ω² = k/m along every coordinate."""
    e = only(equilibria(derive_model(hanging(coordinates)), {"g": g}))
    assert e["q"]["y"] == pytest.approx(-M * g / K, abs=1e-12)
    if "x" in coordinates:
        assert e["q"]["x"] == pytest.approx(0.0, abs=1e-12)
    assert e["kind"] == "stable" and e["stable"]
    assert e["frequencies"] == pytest.approx([math.sqrt(K / M)] * len(coordinates), rel=1e-9)


def test_a_spring_with_rest_length_still_finds_both_sides_of_its_anchor():
    """ℓ₀ = 0.5 and g = 0: k(|y| − ℓ₀) = 0 at y = ±ℓ₀, not at the anchor (the corner of V)."""
    out = equilibria(derive_model(hanging(["y"])), {"g": 0.0, "l0": 0.5})
    assert sorted(e["q"]["y"] for e in out["equilibria"]) == pytest.approx([-0.5, 0.5])


def test_the_elastic_pendulum_with_zero_rest_length_swings_and_bounces_at_root_k_over_m():
    """r₀ = m g/k; K = diag(k, m g r₀), M = diag(m, m r₀²): ω² = k/m and g/r₀ = k/m."""
    p = load_scene("elastic_pendulum")["parameters"]
    e = only(equilibria(derivation_of_scene("elastic_pendulum"), {"l0": 0.0}))
    assert e["q"]["r"] == pytest.approx(p["m"] * p["g"] / p["k"], rel=1e-9)
    assert e["kind"] == "stable"
    assert e["frequencies"] == pytest.approx([math.sqrt(p["k"] / p["m"])] * 2, rel=1e-9)


def test_the_elastic_pendulum_resting_at_its_anchor_is_not_called_no_equilibrium():
    """ℓ₀ = 0 and g = 0: the only rest is r = 0, where the polar coordinates (r > 0) are
    singular. Said so, not 'the forces never balance' (nor a θ family next to 'none')."""
    out = equilibria(derivation_of_scene("elastic_pendulum"), {"l0": 0.0, "g": 0.0})
    assert out["equilibria"] == []
    assert any("r = 0" in w and "declared positive" in w for w in out["warnings"])
    assert not any("never balance" in w for w in out["warnings"])
    assert not any("every value of theta" in w for w in out["warnings"])


def test_the_elastic_pendulum_without_its_spring_cannot_rest_anywhere():
    """k = 0: only gravity acts on the bob, so nothing balances it, not even at r = 0, θ = π/2
    where Q_r = m g cos θ and Q_θ = −m g r sin θ both vanish (an artefact of the polar
    coordinates: gravity still pulls there)."""
    out = equilibria(derivation_of_scene("elastic_pendulum"), {"k": 0.0})
    assert out["equilibria"] == []
    assert not any("can rest" in w for w in out["warnings"])
    assert any("never balance" in w for w in out["warnings"])


# --- 2. families of equilibria ----------------------------------------------------------------


def test_an_atwood_machine_with_equal_masses_is_one_neutral_family():
    """Q_x = (m₁ − m₂) g = 0 for every x when m₁ = m₂: one family, not two dozen samples."""
    out = equilibria(derivation_of_scene("atwood_machine"), {"m1": 1.5, "m2": 1.5})
    e = only(out)
    assert e["free"] == ["x"] and e["kind"] == "marginal" and not e["stable"]
    assert "neutral" in e["reason"]
    assert any("every configuration is an equilibrium" in w for w in out["warnings"])
    assert not any("continuum" in w or "missed" in w for w in out["warnings"])


def test_unequal_masses_have_no_equilibrium():
    out = equilibria(derivation_of_scene("atwood_machine"), {"m1": 2.0, "m2": 1.0})
    assert out["equilibria"] == []


def test_coupled_oscillators_without_wall_springs_are_a_line_of_equilibria():
    """k = 0: only the middle spring, k₁₂(x₂ − x₁) = 0, so x₁ = x₂ (any value); across the line
    the masses beat against each other with ω² = 2k₁₂/m."""
    p = load_scene("coupled_oscillators")["parameters"]
    out = equilibria(derivation_of_scene("coupled_oscillators"), {"k": 0.0})
    e = only(out)
    assert e["q"]["x1"] == pytest.approx(e["q"]["x2"], abs=1e-12)
    assert e["frequencies"] == pytest.approx([math.sqrt(2 * p["k12"] / p["m"])], rel=1e-9)
    assert "neutral" in e["reason"]
    (family,) = [w for w in out["warnings"] if "family" in w]
    assert "(1, 1)" in family
    assert not any("continuum" in w for w in out["warnings"])


def test_a_spring_of_stiffness_zero_with_gravity_along_has_no_equilibrium():
    """k = 0: only m g acts, along y: nothing balances it (and no family note beside 'none')."""
    out = equilibria(derive_model(hanging(["x", "y"])), {"k": 0.0, "l0": 0.0})
    assert out["equilibria"] == []
    assert not any("every value" in w for w in out["warnings"])


def test_a_spring_of_stiffness_zero_without_gravity_is_neutral_everywhere():
    """k = 0 and g = 0: no force at all, every point an equilibrium; the planar spring's
    k ℓ₀/ℓ at the anchor was 0·∞ and refused as 'overflows double precision'."""
    out = equilibria(derive_model(hanging(["x", "y"])), {"k": 0.0, "g": 0.0, "l0": 0.0})
    e = only(out)
    assert sorted(e["free"]) == ["x", "y"] and e["kind"] == "marginal"
    assert "neutral" in e["reason"]


# --- 3. the spherical pendulum at its pole ----------------------------------------------------


def test_the_spherical_pendulum_at_the_bottom_has_two_equal_modes():
    """About the bottom, x = l θ cos φ and z = l θ sin φ: L ≈ ½m(ẋ² + ż²) − ½(m g/l)(x² + z²),
    two independent swings with ω = √(g/l). θ alone shows one; φ is undefined there."""
    p = load_scene("spherical_pendulum")["parameters"]
    omega = math.sqrt(p["g"] / p["l"])
    out = equilibria(derivation_of_scene("spherical_pendulum"), {})
    bottom = next(e for e in out["equilibria"] if abs(e["q"]["theta"]) < 1e-9)
    assert bottom["kind"] == "stable"
    assert bottom["frequencies"] == pytest.approx([omega, omega], rel=1e-9)
    assert len(bottom["modes"]) == 2
    assert "pole" in bottom["reason"] and "degenerate" in bottom["reason"]
    assert sorted(b for _, b in bottom["eigenvalues"]) == pytest.approx(
        [-omega, -omega, omega, omega], rel=1e-9
    )
    top = next(e for e in out["equilibria"] if abs(e["q"]["theta"]) > 3)
    # at the top both directions fall: e^(√(g/l) t), twice
    assert sorted(a for a, _ in top["eigenvalues"]) == pytest.approx(
        [-omega, -omega, omega, omega], rel=1e-9
    )
    # the step says 'any phi' where the panel does, not 'phi = 0'
    lines = out["steps"][1]["plain"]
    assert any(line.startswith("theta = 0, any phi: stable") for line in lines), lines


def test_a_pole_without_the_symmetry_is_not_called_stable():
    """V = −m g l cos θ + ε sin²θ cos 2φ: about the bottom, with x = l θ cos φ, z = l θ sin φ,
    V ≈ ½(m g/l)(x² + z²) + (ε/l²)(x² − z²). With ε = 10 > m g l/2 the bottom is a saddle
    (unstable along z), though θ alone at φ = 0 sees a minimum. The search finds the bottom at
    many φ, all one point: listed once, unstable (it was 'stable' at some φ)."""
    spec = copy.deepcopy(load_scene("spherical_pendulum"))
    p = spec["parameters"]
    spec["parameters"]["e"] = 10.0
    assert p["m"] * p["g"] / p["l"] - 2 * 10.0 / p["l"] ** 2 < 0  # the saddle, by hand
    spec["potentials"] = [{"name": "tilt", "expression": "e*sin(theta)**2*cos(2*phi)"}]
    out = equilibria(derive_model(spec), {})
    (bottom,) = [e for e in out["equilibria"] if abs(e["q"]["theta"]) < 1e-9]  # one point
    assert bottom["kind"] == "unstable" and not bottom["stable"]
    assert any("name one configuration" in w for w in out["warnings"])


# --- 4. eigenvalues listed in the frequencies' order -------------------------------------------


def test_elastic_pendulum_eigenvalues_pair_with_the_frequencies_in_order():
    """At r₀ = l₀ + m g/k, θ = 0: M = diag(m, m r₀²), K = diag(k, m g r₀), C = 0; numpy's
    eigenvalues of [[0, I], [−M⁻¹K, 0]] give the ω; the i-th conjugate pair listed is ±i ω_i."""
    p = load_scene("elastic_pendulum")["parameters"]
    m, k, l0, g = p["m"], p["k"], p["l0"], p["g"]
    r0 = l0 + m * g / k
    Mm, Kk = np.diag([m, m * r0**2]), np.diag([k, m * g * r0])
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(Mm, Kk), np.zeros((2, 2))]])
    expected = sorted(z.imag for z in np.linalg.eigvals(A) if z.imag > 0)
    out = equilibria(derivation_of_scene("elastic_pendulum"), {})
    e = next(e for e in out["equilibria"] if abs(e["q"]["theta"]) < 1e-9)
    assert e["frequencies"] == pytest.approx(expected, rel=1e-9)
    listed = [b for _, b in e["eigenvalues"]]
    assert listed[0::2] == pytest.approx(expected, rel=1e-9)  # +iω₁, +iω₂ ...
    assert listed[1::2] == pytest.approx([-w for w in expected], rel=1e-9)  # ... each with −iω
    text = e["reason"]
    first, second = (text.index(rf"\pm {w:.4g}i") for w in expected)
    assert first < second


def test_an_overflowing_gravity_is_not_blamed_on_coulomb_friction():
    """g = 1e308 on a frictionless pendulum: the linearization overflows, and the 422 says so on
    parameters.g; 'not differentiable (Coulomb friction)' stays for the scene that has it."""
    from fastapi.testclient import TestClient

    from app.main import app

    with TestClient(app) as c:
        r = c.post(
            "/api/v1/equilibria", json={"scene_id": "simple_pendulum", "parameters": {"g": 1e308}}
        )
        assert r.status_code == 422, r.text
        [error] = r.json()["detail"]
        assert error["field"] == "parameters.g" and "overflows" in error["message"]
        assert "friction" not in error["message"].lower()
        r = c.post(
            "/api/v1/equilibria",
            json={"scene_id": "incline_friction", "parameters": {"alpha": 0.0}},
        )
        assert r.status_code == 200 and {e["kind"] for e in r.json()["equilibria"]} == {"marginal"}
