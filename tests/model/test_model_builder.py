"""Trust in the model builder: no false stop, no refusal of a smooth system, and no kinked
position let through.

Zero-rest-length springs: V = ½k|r|² is the isotropic harmonic oscillator, ẍ = −(k/m) x in every
direction, so its orbits are the ellipses x = x₀ cos ωt + (ẋ₀/ω) sin ωt (the same for y) with
ω = √(k/m), and a body released on a line through the anchor passes straight through it. With a
rest length ℓ₀ > 0 the spring's direction is undefined at the anchor (V = ½k(|x| − ℓ₀)² has a
corner there): a run along a line stops there, at the time of x = ℓ₀ + (x₀ − ℓ₀) cos ωt = 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechanics.integrators import METHODS
from mechanics.simulate import SimulationRequest, simulate

M, K = 1.0, 4.0
OMEGA = math.sqrt(K / M)


def spring_spec(coordinates: list[str], rest_length: float, initial: dict) -> dict:
    """A particle on a spring to the origin whose rest length is a parameter (known only at run
    time, so the model cannot tell a zero one from the corner of a stretched one)."""
    position = [*coordinates, *[0] * (3 - len(coordinates))]
    return {
        "title": "Particle on a spring to the origin",
        "coordinates": coordinates,
        "parameters": {"m": M, "k": K, "L0": rest_length},
        "bodies": [{"name": "bob", "mass": "m", "position": position}],
        "springs": [{"name": "spring", "a": "O", "b": "bob", "k": "k", "rest_length": "L0"}],
        "initial": initial,
    }


def request(method: str = "DOP853", **kw) -> SimulationRequest:
    fixed = {"dt": 1e-3} if METHODS[method].kind == "fixed" else {}
    return SimulationRequest(method=method, rtol=1e-11, atol=1e-12, **fixed, **kw)


def oscillator(x0: float, v0: float, t: np.ndarray) -> np.ndarray:
    return x0 * np.cos(OMEGA * t) + v0 / OMEGA * np.sin(OMEGA * t)


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4"])
def test_a_zero_rest_length_spring_on_a_line_passes_through_its_anchor(method):
    """x(t) = x₀ cos ωt for two periods: through x = 0 four times, no stop."""
    period = 2 * math.pi / OMEGA
    spec = spring_spec(["x"], 0.0, {"x": 1.0})
    result = simulate(scene=spec, request=request(method, t_end=2 * period, fps=50))
    assert result["stats"]["status"] == "ok"
    assert "stop" not in result["stats"]
    assert not any(w.startswith("Stopped") for w in result["warnings"])
    t = np.array(result["t"])
    assert t[-1] == pytest.approx(2 * period, abs=0.02)
    tol = 1e-6 if method != "rk4" else 1e-8 * 1e3  # rk4 at dt = 1e-3: error ~ (ωh)⁴ t
    np.testing.assert_allclose(result["q"]["x"], oscillator(1.0, 0.0, t), atol=tol)
    assert min(result["q"]["x"]) < -0.99  # it went through to the other side


def test_a_zero_rest_length_spring_in_the_plane_traces_its_ellipse_with_period_2pi_sqrt_m_over_k():
    x0, vy0 = 1.0, 0.5
    period = 2 * math.pi * math.sqrt(M / K)
    spec = spring_spec(["x", "y"], 0.0, {"x": x0, "y_dot": vy0})
    result = simulate(scene=spec, request=request(t_end=period, fps=200))
    assert result["stats"]["status"] == "ok"
    t = np.array(result["t"])
    x, y = np.array(result["q"]["x"]), np.array(result["q"]["y"])
    np.testing.assert_allclose(x, oscillator(x0, 0.0, t), atol=1e-7)
    np.testing.assert_allclose(y, oscillator(0.0, vy0, t), atol=1e-7)
    # the ellipse (x/x₀)² + (y ω/ẏ₀)² = 1, closed after one period
    np.testing.assert_allclose((x / x0) ** 2 + (y * OMEGA / vy0) ** 2, 1.0, atol=1e-6)
    # y = (ẏ₀/ω) sin ωt changes sign at half the period 2π√(m/k)
    k = int(np.nonzero((y[1:] < 0) & (y[:-1] >= 0))[0][0])
    half = t[k] + (t[k + 1] - t[k]) * y[k] / (y[k] - y[k + 1])
    assert half == pytest.approx(period / 2, abs=1e-4)


def test_a_zero_rest_length_spring_in_the_plane_released_through_the_anchor_stays_on_its_line():
    spec = spring_spec(["x", "y"], 0.0, {"x": 1.0, "y": 0.0})
    result = simulate(scene=spec, request=request(t_end=3.0, fps=50))
    assert result["stats"]["status"] == "ok" and "stop" not in result["stats"]
    t = np.array(result["t"])
    np.testing.assert_allclose(result["q"]["x"], np.cos(OMEGA * t), atol=1e-6)
    np.testing.assert_allclose(result["q"]["y"], 0.0, atol=1e-9)


def test_a_zero_rest_length_spring_may_start_at_its_anchor():
    """At the anchor with a velocity: x = (v₀/ω) sin ωt, not a refusal ('zero length')."""
    spec = spring_spec(["x"], 0.0, {"x": 0.0, "x_dot": 2.0})
    result = simulate(scene=spec, request=request(t_end=3.0, fps=50))
    assert result["stats"]["status"] == "ok"
    t = np.array(result["t"])
    np.testing.assert_allclose(result["q"]["x"], oscillator(0.0, 2.0, t), atol=1e-6)


@pytest.mark.parametrize("method", ["DOP853", "dop853_c"])
def test_a_stretched_spring_still_stops_at_its_anchor(method):
    """ℓ₀ = 0.5, x₀ = 1.5: x = 0.5 + cos ωt reaches the anchor at ωt = 2π/3."""
    spec = spring_spec(["x"], 0.5, {"x": 1.5})
    result = simulate(scene=spec, request=request(method, t_end=3.0, fps=50))
    stop = result["stats"]["stop"]
    assert stop["name"] == "spring_at_anchor"
    assert stop["t"] == pytest.approx(2 * math.pi / 3 / OMEGA, abs=1e-6)


def test_the_same_spec_with_the_rest_length_overridden_to_zero_passes_through():
    """One compiled scene, two runs: the stop is decided by the run's parameter, not the spec's."""
    spec = spring_spec(["x"], 0.5, {"x": 1.5})
    result = simulate(scene=spec, request=request(t_end=3.0, fps=50, parameters={"L0": 0.0}))
    assert result["stats"]["status"] == "ok"
    t = np.array(result["t"])
    np.testing.assert_allclose(result["q"]["x"], oscillator(1.5, 0.0, t), atol=1e-6)


# --- reasons that are true: k = 0, g = 1e308 ----------------------------------------------------


def test_a_spring_with_zero_stiffness_leaves_a_free_particle():
    """k = 0: no force at all, x = x₀ + v₀ t (it was said to give an 'overflow' reason)."""
    spec = spring_spec(["x", "y"], 0.5, {"x": 1.0, "x_dot": 0.3, "y_dot": -0.2})
    result = simulate(scene=spec, request=request(t_end=2.0, fps=10, parameters={"k": 0.0}))
    assert result["stats"]["status"] == "ok"
    t = np.array(result["t"])
    np.testing.assert_allclose(result["q"]["x"], 1.0 + 0.3 * t, atol=1e-9)
    np.testing.assert_allclose(result["q"]["y"], -0.2 * t, atol=1e-9)
    assert result["warnings"] == []


@pytest.mark.parametrize("scene", ["simple_pendulum", "incline_friction", "atwood_machine"])
def test_an_overflowing_gravity_is_refused_naming_it_and_saying_overflow(scene):
    """g = 1e308: q̈ is finite at the start (g sin θ₀ < 1.8e308) and the first step overflows.
    It answered a one-sample 'partial' run ('the right-hand side became non-finite at
    t = 3.46e-323 s'); the reason is the size of g, named as a start that overflows is."""
    from fastapi.testclient import TestClient

    from app.main import app

    with TestClient(app) as client:
        r = client.post(
            "/api/v1/simulate", json={"scene_id": scene, "parameters": {"g": 1e308}, "t_end": 2}
        )
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["field"] == "parameters.g"
    assert "overflow" in error["message"] and "g = 1e+308" in error["message"]
    assert "friction" not in error["message"].lower()


def test_an_ordinary_blow_up_is_not_blamed_on_the_units():
    """ẍ = x²: from x₀ = 1 at rest it reaches infinity in finite time, for ordinary numbers;
    the run says where it stopped and names no parameter."""
    spec = {
        "coordinates": ["x"],
        "parameters": {"m": 1.0},
        "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
        "potentials": [{"name": "cubic", "expression": "-m*x**3/3"}],
        "initial": {"x": 1.0},
    }
    result = simulate(scene=spec, request=request(t_end=5.0, fps=10))
    assert result["stats"]["status"] != "ok"
    assert not any("overflows double precision" in w for w in result["warnings"])


def test_a_zero_rest_length_spring_at_its_anchor_raises_no_warning():
    """V = ½ k x² is smooth at the anchor: no 'it has no direction' warning when the spec's own
    state starts there with ℓ₀ = 0; a stretched spring (ℓ₀ = 0.5) at its anchor keeps it."""
    from mechanics.derive import derive_model

    def warnings(rest_length: float) -> list[str]:
        spec = spring_spec(["x"], rest_length, {"x": 0.0, "x_dot": 2.0})
        return [w for w in derive_model(spec).work.warnings if "at its anchor" in w]

    assert warnings(0.0) == []
    assert len(warnings(0.5)) == 1
