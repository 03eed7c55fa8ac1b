"""A fixed-step run takes exactly the step asked for, and says so.

The student picks dt to see what a step costs and how accurate it is: a run that silently
replaced dt by (1/fps)/⌈(1/fps)/dt⌉ (rk4 at dt = 100 and at dt = 0.5 gave the same run) taught
the wrong lesson. The expected values here come from integrators written in this file for the
pendulum's own equation θ̈ = −(g/l) sin θ, stepped at exactly dt.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.main import app

G, L, THETA0 = 9.81, 1.0, 2.0  # the built-in simple_pendulum's parameters and start


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def _accel(theta: float) -> float:
    return -G / L * math.sin(theta)


def euler(dt: float, steps: int) -> list[tuple[float, float]]:
    """Explicit Euler at exactly dt: every state, from the start."""
    th, w, out = THETA0, 0.0, [(THETA0, 0.0)]
    for _ in range(steps):
        th, w = th + dt * w, w + dt * _accel(th)
        out.append((th, w))
    return out


def rk4(dt: float, steps: int) -> list[tuple[float, float]]:
    """Classical RK4 at exactly dt on y = (θ, ω)."""

    def f(y):
        return np.array([y[1], _accel(y[0])])

    y, out = np.array([THETA0, 0.0]), [(THETA0, 0.0)]
    for _ in range(steps):
        k1 = f(y)
        k2 = f(y + dt / 2 * k1)
        k3 = f(y + dt / 2 * k2)
        k4 = f(y + dt * k3)
        y = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append((float(y[0]), float(y[1])))
    return out


def run(client, **body) -> dict:
    r = client.post("/api/v1/simulate", json={"scene_id": "simple_pendulum", **body})
    assert r.status_code == 200, r.text
    return r.json()


@pytest.mark.parametrize("dt", [0.05, 0.02, 0.01, 0.03])
def test_euler_takes_exactly_the_step_asked_for(client, dt):
    """Every sample is the hand-written Euler's state at that many steps of exactly dt."""
    out = run(client, method="euler", dt=dt, t_end=10, fps=30)
    t = np.array(out["t"])
    steps = np.rint(t / dt).astype(int)
    assert np.allclose(t, steps * dt, rtol=0, atol=1e-12)  # samples on the step grid
    mine = euler(dt, int(steps[-1]))
    theta = [mine[k][0] for k in steps]
    omega = [mine[k][1] for k in steps]
    assert np.allclose(out["q"]["theta"], theta, rtol=1e-10, atol=1e-12)
    assert np.allclose(out["q_dot"]["theta"], omega, rtol=1e-10, atol=1e-12)
    assert out["stats"]["steps"] == steps[-1]
    assert out["stats"]["dt"] == dt


def test_the_step_count_is_t_end_over_dt_and_the_page_menu_values_all_differ(client):
    """The hostile finding: dt = 0.05 ran 300 steps over 10 s (1/30 s each)."""
    seen = {}
    for dt in (0.05, 0.02, 0.01):
        st = run(client, method="euler", dt=dt, t_end=10, fps=30)["stats"]
        assert st["steps"] == round(10 / dt)
        seen[dt] = st["steps"]
        # samples a whole number of steps apart, near 1/fps
        k = st["sample_interval"] / dt
        assert abs(k - round(k)) < 1e-9 and 0.5 / 30 <= st["sample_interval"] <= max(dt, 2 / 30)
    assert len(set(seen.values())) == 3


def test_rk4_at_a_long_step_is_its_own_run(client):
    """dt = 0.5 is 20 rk4 steps over 10 s, not 600 steps of 1/60 s."""
    out = run(client, method="rk4", dt=0.5, t_end=10, fps=60)
    assert out["stats"]["steps"] == 20
    assert np.allclose(out["t"], np.arange(21) * 0.5)
    mine = rk4(0.5, 20)
    assert np.allclose(out["q"]["theta"], [s[0] for s in mine], rtol=1e-10, atol=1e-12)


def test_a_step_longer_than_the_run_is_refused_naming_dt(client):
    r = client.post(
        "/api/v1/simulate", json={"scene_id": "simple_pendulum", "method": "rk4", "dt": 100}
    )
    assert r.status_code == 422
    fields = [e["field"] for e in r.json()["detail"]]
    assert fields == ["dt"], r.json()


def test_a_t_end_that_is_not_whole_steps_says_where_the_run_ends(client):
    out = run(client, method="rk4", dt=0.3, t_end=1, fps=30)
    assert out["t"][-1] == pytest.approx(0.9)
    assert out["stats"]["steps"] == 3
    assert any("short of t_end" in w for w in out["warnings"])


def test_adaptive_runs_keep_the_fps_grid(client):
    out = run(client, method="DOP853", t_end=1, fps=30, check_sensitivity=False)
    assert len(out["t"]) == 31 and out["stats"]["sample_interval"] == pytest.approx(1 / 30)
    assert "dt" not in out["stats"] or out["stats"]["dt"] is None


BLOW_UP = {
    "title": "Spring with a cubic push",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 4.0, "c": 0.1},
    "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
    "springs": [{"a": "O", "b": "b", "k": "k"}],
    "forces": [{"on": "b", "vector": ["c*x_dot**3", 0, 0]}],
    "initial": {"x": 0.5},
}


def test_a_finite_time_blow_up_is_told_as_one_not_as_stiffness(client):
    """ẍ = −4x + 0.1ẋ³ feeds energy in faster than it grows: integrated here with scipy, |ẋ|
    passes 1e5 before t = 14 s. The run must say the solution grows without bound, and must not
    send the student to Radau or BDF for a stiffness that is not there."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        return [y[1], -4 * y[0] + 0.1 * y[1] ** 3]

    def big(t, y):
        return abs(y[1]) - 1e5

    big.terminal = True
    mine = solve_ivp(rhs, (0, 20), [0.5, 0.0], rtol=1e-10, atol=1e-12, events=big)
    assert mine.status == 1 and mine.t_events[0][0] < 14  # it does blow up
    for method in ("DOP853", "dop853_c", "RK45"):
        r = client.post(
            "/api/v1/simulate",
            json={"scene": BLOW_UP, "method": method, "t_end": 20, "fps": 30},
        ).json()
        assert r["stats"]["status"] == "stopped"
        text = " ".join(r["warnings"])
        assert "grows without bound" in text and "Radau" not in text, (method, r["warnings"])
        assert r["t"][-1] <= mine.t_events[0][0] + 0.1


def test_an_overflowing_fixed_step_says_so_in_words(client):
    """rk4 at dt = 0.01 heading for the spherical pendulum's pole: φ̇ = p/sin²θ is huge there and
    the fixed step overflows; an adaptive run of the same start goes through (the motion is
    finite), so the words must name the step, not a Python error."""
    initial = {"theta": 0.5, "theta_dot": -3, "phi_dot": 0.01}
    body = {"scene_id": "spherical_pendulum", "initial": initial, "t_end": 3}
    fixed = run(client, **body, method="rk4", dt=0.01)
    adaptive = run(client, **body, method="DOP853", check_sensitivity=False)
    assert adaptive["stats"]["status"] == "ok"
    assert fixed["stats"]["status"] == "stopped"
    text = " ".join(fixed["warnings"])
    assert "OverflowError" not in text and "34" not in text
    assert "smaller dt" in text and "adaptive" in text
