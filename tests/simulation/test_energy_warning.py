"""The accuracy warning says what the energy error did, at its honest size.

An instructor's play-test: symplectic Euler on the pendulum (dt = 0.01) was told its energy
"drifted" and to pick a higher-order method, though the error was the same at t_end = 10 and 100
(a symplectic method's bounded oscillation), and explicit Euler's energy, which grew tenfold, was
reported as 0.75 "of the kinetic energy" (divided by the largest T of the wrong run itself).
Every expected value here comes from the returned q, q̇ and this file's own energy of the
pendulum, E = ½ m l² θ̇² − m g l cos θ, and its kinetic-energy scale at E0, E0 + m g l (the
kinetic energy at the bottom).
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.scenes import scene_ids
from mechanics.simulate import _error_trend

M, L, G = 1.0, 1.0, 9.81  # the built-in simple_pendulum's parameters
NUMBER = r"(-?[0-9.]+(?:e[-+]?[0-9]+)?)"


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def run(client, **body) -> dict:
    r = client.post("/api/v1/simulate", json={"scene_id": "simple_pendulum", **body})
    assert r.status_code == 200, r.text
    return r.json()


def energy(body: dict) -> np.ndarray:
    th, w = np.array(body["q"]["theta"]), np.array(body["q_dot"]["theta"])
    return 0.5 * M * L**2 * w**2 - M * G * L * np.cos(th)


def accuracy_warnings(body: dict) -> list[str]:
    return [w for w in body["warnings"] if "kinetic-energy scale" in w]


@pytest.mark.parametrize("t_end", [10.0, 100.0])
def test_symplectic_euler_is_told_its_error_oscillates_not_that_it_drifts(client, t_end):
    body = run(client, method="symplectic_euler", dt=0.01, t_end=t_end)
    E = energy(body)
    err = np.abs(E - E[0])
    half = len(E) // 2
    # the claim's evidence, measured here: the same largest deviation in both halves
    assert np.max(err[half:]) == pytest.approx(np.max(err[:half]), rel=0.02)
    (said,) = accuracy_warnings(body)
    assert "drift" not in said and "higher-order" not in said
    assert "oscillates" in said and "bounded" in said and "smaller step" in said
    lo, hi = (float(x) for x in re.search(f"between {NUMBER} J and {NUMBER} J", said).groups())
    assert lo == pytest.approx(E.min(), rel=5e-3) and hi == pytest.approx(E.max(), rel=5e-3)
    share = float(re.search(f"within {NUMBER}%", said).group(1)) / 100
    assert share == pytest.approx(err.max() / (E[0] + M * G * L), rel=0.05)


def test_symplectic_euler_error_is_the_same_at_t_end_10_and_100(client):
    said = [
        accuracy_warnings(run(client, method="symplectic_euler", dt=0.01, t_end=t))
        for t in (10.0, 100.0)
    ]
    assert said[0] == said[1]


def test_explicit_euler_is_told_its_energy_grew_at_its_true_size(client):
    body = run(client, method="euler", dt=0.01, t_end=100.0)
    E = energy(body)
    worst = int(np.argmax(np.abs(E - E[0])))
    assert E[worst] > 10 * E[0]  # the run's own growth, measured here
    (said,) = accuracy_warnings(body)
    assert said.startswith("E drifts:") and "grows with the length of the run" in said
    start, end = (float(x) for x in re.search(f"grew from {NUMBER} J to {NUMBER} J", said).groups())
    assert start == pytest.approx(E[0], rel=5e-3) and end == pytest.approx(E[worst], rel=5e-3)
    times = float(re.search(f"{NUMBER} times the motion's kinetic-energy scale", said).group(1))
    assert times == pytest.approx((E[worst] - E[0]) / (E[0] + M * G * L), rel=0.05)
    scale = float(re.search(f"kinetic-energy scale \\({NUMBER} J\\)", said).group(1))
    assert scale == pytest.approx(E[0] + M * G * L, rel=5e-3)  # not max T of the wrong run
    assert "symplectic" in said  # the method whose error would stay bounded


def test_rk4_slow_loss_is_a_drift_downwards(client):
    body = run(client, method="rk4", dt=0.1, t_end=100.0)
    E = energy(body)
    third = len(E) // 3
    assert E[-third:].max() < E[:third].min()  # it really loses energy for good
    (said,) = accuracy_warnings(body)
    assert said.startswith("E drifts: it fell from")


def test_a_run_too_short_for_a_swing_is_not_classified(client):
    body = run(client, method="symplectic_euler", dt=0.01, t_end=0.5)
    (said,) = accuracy_warnings(body)
    assert "drift" not in said and "oscillates" not in said
    assert re.search(f"fell from {NUMBER} J to {NUMBER} J", said)


def test_error_trend_on_known_shapes():
    t = np.linspace(0.0, 20.0, 2001)
    qd = np.cos(t)[None, :]  # a few swings in each half
    assert _error_trend(0.01 * np.sin(t) ** 2, qd) == "bounded"
    assert _error_trend(1e-3 * t, qd) == "grows"  # linear: twice the size in the second half
    assert _error_trend(1e-3 * (np.exp(0.2 * t) - 1), qd) == "grows"
    assert _error_trend(-1e-3 * t + 1e-4 * np.sin(5 * t), qd) == "grows"
    assert _error_trend(1e-3 * t, np.ones_like(qd)) == "unknown"  # no swing: cannot tell


@pytest.mark.parametrize("scene_id", scene_ids())
def test_no_catalog_scene_gets_an_accuracy_warning_at_default_settings(client, scene_id):
    r = client.post("/api/v1/simulate", json={"scene_id": scene_id})
    assert r.status_code == 200, r.text
    assert accuracy_warnings(r.json()) == []
    assert math.isfinite(r.json()["t"][-1])
