"""Runs end where their model stops holding, at the moment a closed form (or our own event
search on hand-written equations) puts it.

Atwood machine: x = ½ a t², a = (m1 − m2) g / (m1 + m2), a mass reaches the pulley at x = l + d
(or x = −d). Incline: a block decelerating at g(μ cos α − sin α) sticks at t = v0 / that; with
μ < tan α it reverses and slides down (a piecewise parabola). A projectile lands at the root of
y0 + v t − ½ g t². A pendulum's string goes slack where m(g cos θ + l θ̇²) reaches 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.integrate import solve_ivp

from app.main import app
from mechanics.integrators import METHODS
from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError

TIGHT = {"rtol": 1e-11, "atol": 1e-12}


def request_for(method: str, **kw) -> SimulationRequest:
    fixed = {"dt": 0.01} if METHODS[method].kind == "fixed" else {}
    return SimulationRequest(method=method, **fixed, **kw)


# --- Atwood machine ----------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4", "Radau"])
def test_atwood_heavier_mass1_stops_when_mass2_reaches_the_pulley(method):
    p = load_scene("atwood_machine")["parameters"]
    accel = (p["m1"] - p["m2"]) * p["g"] / (p["m1"] + p["m2"])
    t_stop = math.sqrt(2 * (p["l"] + p["d"]) / accel)
    result = simulate(scene_id="atwood_machine", request=request_for(method, t_end=3.0, fps=50))
    stop = result["stats"]["stop"]
    assert stop["name"] == "mass2_at_pulley"
    assert stop["t"] == pytest.approx(t_stop, abs=1e-6)
    assert result["t"][-1] == pytest.approx(t_stop, abs=1e-6)
    assert result["q"]["x"][-1] == pytest.approx(p["l"] + p["d"], abs=1e-6)
    assert result["stats"]["status"] == "stopped"
    assert any(w.startswith("Stopped at") for w in result["warnings"])


def test_atwood_heavier_mass2_stops_when_mass1_reaches_the_pulley():
    p = load_scene("atwood_machine")["parameters"]
    m1, m2 = 1.0, 2.5
    accel = (m1 - m2) * p["g"] / (m1 + m2)  # < 0: x falls to −d
    t_stop = math.sqrt(2 * p["d"] / -accel)
    result = simulate(
        scene_id="atwood_machine",
        request=SimulationRequest(parameters={"m1": m1, "m2": m2}, t_end=3.0, fps=50),
    )
    assert result["stats"]["stop"]["name"] == "mass1_at_pulley"
    assert result["stats"]["stop"]["t"] == pytest.approx(t_stop, abs=1e-6)
    assert result["q"]["x"][-1] == pytest.approx(-p["d"], abs=1e-6)


@pytest.mark.parametrize("x0", [1.5, -0.5])
def test_atwood_starting_beyond_the_pulley_is_refused(x0):
    with pytest.raises(SpecError) as err:
        simulate(scene_id="atwood_machine", request=SimulationRequest(initial={"x": x0}, t_end=1.0))
    assert any(e["field"].startswith("initial") for e in err.value.errors)


# --- incline with Coulomb friction ------------------------------------------------------------


@pytest.mark.parametrize("method", list(METHODS))
def test_incline_with_enough_friction_sticks_at_v0_over_the_deceleration(method):
    spec = load_scene("incline_friction")
    p = {**spec["parameters"], "mu": 0.8}
    v0 = spec["initial"]["s_dot"]
    decel = p["g"] * (p["mu"] * math.cos(p["alpha"]) - math.sin(p["alpha"]))
    assert decel > 0
    t_stick = v0 / decel
    result = simulate(
        scene_id="incline_friction",
        request=request_for(method, parameters={"mu": 0.8}, t_end=2.0, fps=50, **TIGHT),
    )
    stop = result["stats"]["stop"]
    assert stop["name"] == "sticks"
    assert stop["t"] == pytest.approx(t_stick, abs=1e-6)
    assert result["t"][-1] == pytest.approx(t_stick, abs=1e-6)


FIXED = [m for m in METHODS if METHODS[m].kind == "fixed"]


@pytest.mark.parametrize("method", list(METHODS))
def test_a_stuck_block_is_at_rest_where_its_last_sample_says(method):
    """The last sample is the state at the stop: s_dot = 0, and s follows from the sample before
    it by the exact constant-deceleration motion — exactly for adaptive methods; for a fixed-step
    one up to its own error over the steps between that sample and the stop (a h² per step for
    first-order methods, whose state at the last step before the stop is that step's)."""
    p = {**load_scene("incline_friction")["parameters"], "mu": 0.8}
    decel = p["g"] * (p["mu"] * math.cos(p["alpha"]) - math.sin(p["alpha"]))
    result = simulate(
        scene_id="incline_friction",
        request=request_for(method, parameters={"mu": 0.8}, t_end=2.0, fps=50, **TIGHT),
    )
    t, s, v = result["t"], result["q"]["s"], result["q_dot"]["s"]
    assert v[-1] == pytest.approx(0.0, abs=1e-6)
    gap = t[-1] - t[-2]
    slack = 1e-8 if method not in FIXED else decel * 0.01**2 * math.ceil(gap / 0.01)
    assert s[-1] - s[-2] == pytest.approx(v[-2] * gap - decel * gap**2 / 2, abs=slack)


def test_incline_with_little_friction_reverses_and_slides_down_as_the_piecewise_closed_form():
    p = load_scene("incline_friction")["parameters"]
    g, mu, alpha = p["g"], p["mu"], p["alpha"]
    assert mu < math.tan(alpha)
    v0 = -3.0  # thrown up the slope
    up = g * (math.sin(alpha) + mu * math.cos(alpha))  # friction helps gravity while going up
    down = g * (math.sin(alpha) - mu * math.cos(alpha))  # and opposes it coming down
    t_turn = -v0 / up
    s_turn = v0 * t_turn + up * t_turn**2 / 2

    def closed_form(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        before = t <= t_turn
        s = np.where(before, v0 * t + up * t**2 / 2, s_turn + down * (t - t_turn) ** 2 / 2)
        v = np.where(before, v0 + up * t, down * (t - t_turn))
        return s, v

    result = simulate(
        scene_id="incline_friction",
        request=SimulationRequest(initial={"s_dot": v0}, t_end=2.0, fps=50, **TIGHT),
    )
    assert "stop" not in result["stats"]
    assert result["stats"]["status"] == "ok"
    t = np.array(result["t"])
    assert t[-1] == pytest.approx(2.0)
    s, v = closed_form(t)
    np.testing.assert_allclose(result["q"]["s"], s, atol=1e-6)
    np.testing.assert_allclose(result["q_dot"]["s"], v, atol=1e-6)


# --- a posted spec's own stops ----------------------------------------------------------------

G = 9.81


def projectile(y0: float) -> dict:
    return {
        "title": "Projectile that lands",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "g": G},
        "bodies": [{"name": "ball", "mass": "m", "position": ["x", "y", 0]}],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
        "stops": [{"name": "lands", "when": "y", "message": "the ball reaches the ground"}],
        "initial": {"x": 0.0, "y": y0, "x_dot": 2.0, "y_dot": 5.0},
    }


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4", "LSODA"])
@pytest.mark.parametrize("y0", [0.0, 2.0])
def test_a_projectile_stops_at_its_closed_form_flight_time(method, y0):
    vy = 5.0
    t_flight = (vy + math.sqrt(vy**2 + 2 * G * y0)) / G
    result = simulate(scene=projectile(y0), request=request_for(method, t_end=3.0, fps=30))
    stop = result["stats"]["stop"]
    assert stop["name"] == "lands"
    assert stop["t"] == pytest.approx(t_flight, abs=1e-6)
    assert result["q"]["x"][-1] == pytest.approx(2.0 * t_flight, abs=1e-6)
    assert result["q"]["y"][-1] == pytest.approx(0.0, abs=1e-6)


def test_a_posted_stop_is_reported_through_the_api():
    vy = 5.0
    with TestClient(app) as client:
        response = client.post(
            "/api/v1/simulate", json={"scene": projectile(0.0), "t_end": 3.0, "fps": 30}
        )
    assert response.status_code == 200, response.text
    stats = response.json()["stats"]
    assert stats["status"] == "stopped"
    assert stats["stop"]["name"] == "lands"
    assert stats["stop"]["t"] == pytest.approx(2 * vy / G, abs=1e-6)


SLACK = {
    "title": "Pendulum on a string",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": G},
    "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]}],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    "stops": [{"name": "slack", "tension": "bob", "message": "the string goes slack"}],
}


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4"])
def test_a_string_goes_slack_where_its_tension_reaches_zero(method):
    m, length = 1.0, 1.0
    omega0 = math.sqrt(
        3.5 * G / length
    )  # above the horizontal, short of looping: the string slackens

    def swing(t, y):
        return [y[1], -G / length * math.sin(y[0])]

    def tension(t, y):
        return m * (G * math.cos(y[0]) + length * y[1] ** 2)

    tension.terminal, tension.direction = True, -1
    own = solve_ivp(swing, (0, 3), [0.0, omega0], rtol=1e-12, atol=1e-13, events=tension)
    (t_slack,) = own.t_events[0]
    # energy: l θ̇² = l ω0² − 2g(1 − cos θ), so the tension vanishes at cos θ = (2g − l ω0²)/(3g)
    theta_slack = math.acos((2 * G - length * omega0**2) / (3 * G))
    assert own.y_events[0][0][0] == pytest.approx(theta_slack, abs=1e-8)

    result = simulate(
        scene=SLACK,
        request=request_for(
            method, initial={"theta": 0.0, "theta_dot": omega0}, t_end=3.0, fps=30, **TIGHT
        ),
    )
    stop = result["stats"]["stop"]
    assert stop["name"] == "slack"
    assert stop["t"] == pytest.approx(t_slack, abs=1e-6)
    assert result["q"]["theta"][-1] == pytest.approx(theta_slack, abs=1e-6)
    assert any("slack" in w for w in result["warnings"])


def test_a_string_that_stays_taut_does_not_stop():
    result = simulate(
        scene=SLACK,
        request=SimulationRequest(initial={"theta": 0.0, "theta_dot": 1.0}, t_end=3.0, fps=30),
    )
    assert "stop" not in result["stats"]
    assert result["stats"]["status"] == "ok"


def test_a_particle_released_from_rest_in_the_cone_stops_at_the_vertex():
    """Without angular momentum the particle slides straight down the cone's wall:
    m(1 + cot²α) r̈ = −m g cot α, so r̈ = −g sin α cos α and it reaches r = 0 at
    t = √(2 r₀ / (g sin α cos α)). Past that a negative r is the cone's mirror image below the
    vertex (it used to fall for ever there): the run ends at the vertex and says so."""
    alpha, g, r0 = 0.5, 9.81, 0.5
    req = SimulationRequest(t_end=5, fps=60, initial={"r": r0, "phi_dot": 0.0})
    run = simulate("particle_in_cone", None, req)
    expected = math.sqrt(2 * r0 / (g * math.sin(alpha) * math.cos(alpha)))
    assert run["stats"]["status"] == "stopped"
    assert run["stats"]["stop"]["name"] == "at_vertex"
    assert run["stats"]["stop"]["t"] == pytest.approx(expected, rel=1e-6)
    assert any("vertex" in w for w in run["warnings"])
    assert min(run["q"]["r"]) >= -1e-9


def test_the_cone_refuses_a_start_on_or_below_its_vertex():
    for r in (0.0, -0.2):
        with pytest.raises(SpecError) as refused:
            simulate("particle_in_cone", None, SimulationRequest(initial={"r": r}))
        assert [e["field"] for e in refused.value.errors] == ["initial.r"]
