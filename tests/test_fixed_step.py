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
