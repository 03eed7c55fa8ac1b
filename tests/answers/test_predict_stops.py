"""A prediction ends where the scene's model ends: at its stops, for the true motion and the
answer's alike (POST /api/v1/check/predict on the Atwood machine).

Every expected number is computed here from the scene file alone: the masses, g and the pulley
geometry read from mechanics/scenes/atwood_machine.toml, where each mass meets the pulley solved
with sympy from the positions written there, and the motion from the closed form of uniform
acceleration, x(t) = x₀ + ½ a t², a = ((m₁ − m₂) g + Q)/(m₁ + m₂) for an answer Q_x (the true
Q_x is 0: gravity is in V). Play-test: Q_x = g (m₁ − m₂) was compared 5 s past the pulley
("parts at 1.00 s … 200% of the largest kinetic energy (401) in 5.00 s", the masses 80 m apart).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app

SCENE = tomllib.loads(
    (Path(__file__).parents[2] / "mechanics/scenes/atwood_machine.toml").read_text()
)
P = SCENE["parameters"]
M1, M2, G = P["m1"], P["m2"], P["g"]
X0 = SCENE["initial"]["x"]
assert SCENE["initial"]["x_dot"] == 0  # the closed forms below start from rest
FPS = 60  # the prediction's sample rate (its documented 60 per second)
PART_FRACTION = 0.02  # its documented rule: a body 2 % of the scene's size from the truth


def _positions(axis: int) -> dict[str, sp.Expr]:
    """One coordinate (0: across, 1: up) of each mass and of the pulley, as the scene file
    writes them, at the file's parameter values."""
    x = sp.Symbol("x")
    names = {k: sp.Symbol(k) for k in P} | {"x": x}
    values = {names[k]: v for k, v in P.items()}
    (pulley,) = SCENE["points"]
    written = {b["name"]: b["position"] for b in SCENE["bodies"]} | {"pulley": pulley["position"]}
    return {k: sp.sympify(v[axis], locals=names).subs(values) for k, v in written.items()}


HEIGHTS, ACROSS = _positions(1), _positions(0)
X = sp.Symbol("x")
#: x where each mass reaches the pulley's height (mass2 rising as x grows, mass1 as x falls)
AT_PULLEY = {
    name: float(sp.solve(sp.Eq(HEIGHTS[name], HEIGHTS["pulley"]), X)[0])
    for name in ("mass1", "mass2")
}


def acceleration(q_answer: float = 0.0) -> float:
    return ((M1 - M2) * G + q_answer) / (M1 + M2)


def stop_time(a: float) -> tuple[float, str]:
    """When x₀ + ½ a t² first reaches a mass's pulley position, and which mass."""
    name = "mass2" if a > 0 else "mass1"
    return math.sqrt(2 * (AT_PULLEY[name] - X0) / a), name


def kinetic(a: float, t: float) -> float:
    return 0.5 * (M1 + M2) * (a * t) ** 2


def true_energy(a: float, t: float) -> float:
    """E = T + V of the scene along x = x₀ + ½ a t² (V of both masses from their heights)."""
    x = X0 + 0.5 * a * t**2
    h1, h2 = (float(HEIGHTS[k].subs(X, x)) for k in ("mass1", "mass2"))
    return kinetic(a, t) + G * (M1 * h1 + M2 * h2)


def parting_time(a_true: float, a_answer: float, t_end: float) -> float | None:
    """The first sample at which a mass is 2 % of the scene's size from where it truly is: the
    size is the diagonal of the box around the pulley and both masses' true tracks to t_end."""
    x_end = X0 + 0.5 * a_true * t_end**2
    xs = [float(v) for v in ACROSS.values()]  # the masses hang straight: constant across
    ys = [float(HEIGHTS["pulley"])] + [
        float(HEIGHTS[k].subs(X, x)) for k in ("mass1", "mass2") for x in (X0, x_end)
    ]
    size = math.hypot(max(xs) - min(xs), max(ys) - min(ys))
    for k in range(int(t_end * FPS) + 1):
        t = k / FPS
        if 0.5 * abs(a_answer - a_true) * t**2 > PART_FRACTION * size:
            return t
    return None


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def post_predict(client, answer: str, **extra):
    """The Atwood machine's Q_x answer sent to /check/predict (extra: initial, parameters…)."""
    body = {"scene_id": "atwood_machine", "quantity": "Q", "coordinate": "x", "answer": answer}
    return client.post("/api/v1/check/predict", json={**body, **extra})


def predict(client, answer: str, **extra) -> dict:
    r = post_predict(client, answer, **extra)
    assert r.status_code == 200, r.text[:500]
    return r.json()


def test_the_true_motion_ends_where_mass2_reaches_the_pulley(client):
    """Q_x = −(m₁ − m₂) g/2 is slower than the truth (a = g/6 against g/3): the true motion
    reaches the pulley first, and every figure is of the time before it."""
    a, a_answer = acceleration(), acceleration(-(M1 - M2) * G / 2)
    t_stop, who = stop_time(a)
    assert who == "mass2" and stop_time(a_answer)[0] > t_stop  # the case this test is about
    body = predict(client, "-(m1-m2) g/2")
    true, student = body["true"], body["student"]
    assert true["reached"] == pytest.approx(t_stop, rel=1e-7)
    assert true["t"][-1] == pytest.approx(t_stop, rel=1e-7)
    assert "mass2 reaches the pulley" in true["stopped_because"]
    assert true["q"]["x"][-1] == pytest.approx(AT_PULLEY["mass2"], rel=1e-7)
    # the answer's motion is compared up to then, from the same samples
    assert student["t"] == true["t"]
    assert student["stopped_because"] is None and student["blew_up_at"] is None
    assert student["q"]["x"][-1] == pytest.approx(X0 + 0.5 * a_answer * t_stop**2, rel=1e-7)
    # nothing drawn through the pulley: the scene stays its own size
    pulley = float(HEIGHTS["pulley"])
    for run in (true, student):
        for name in ("mass1", "mass2"):
            assert max(run["positions"][name]["y"]) <= pulley + 1e-9
    # the largest kinetic energy is the true motion's at the pulley, ½(m₁ + m₂)(a t_stop)²
    assert body["energy_scale"] == pytest.approx(kinetic(a, t_stop), rel=1e-7)
    assert body["energy_until"] == pytest.approx(t_stop, rel=1e-7)
    drift = true_energy(a_answer, t_stop) - true_energy(a_answer, 0.0)  # the true E is constant
    assert body["energy_change"] == pytest.approx(drift / kinetic(a, t_stop), rel=1e-6)
    assert body["energy_change"] < 0
    assert body["parted_at"] == pytest.approx(parting_time(a, a_answer, t_stop), abs=1e-9)
    summary = body["summary"]
    assert f"The true motion ends at t = {t_stop:.2f} s (mass2 reaches the pulley" in summary
    assert f"in {t_stop:.2f} s" in summary
    # the yardstick with its unit and its window (the run is cut at the pulley)
    assert f"energy up to t = {t_stop:.2f} s ({kinetic(a, t_stop):.3g} J)" in summary
    assert "5.00 s" not in summary and "Your answer's motion ends" not in summary


@pytest.mark.parametrize(
    ("answer", "q_answer"),
    [("g (m1-m2)", (M1 - M2) * G), ("-2 (m1-m2) g", -2 * (M1 - M2) * G)],
    ids=["mass2 first (the play-test's answer)", "mass1 the other way"],
)
def test_an_answer_whose_motion_stops_first_ends_the_comparison_there(client, answer, q_answer):
    """Q_x = g (m₁ − m₂) doubles the acceleration: its mass2 reaches the pulley before the true
    one does. Q_x = −2 (m₁ − m₂) g reverses it: its mass1 reaches the pulley first."""
    a, a_answer = acceleration(), acceleration(q_answer)
    t_true, true_who = stop_time(a)
    t_answer, who = stop_time(a_answer)
    assert t_answer < t_true  # the case this test is about
    body = predict(client, answer)
    true, student = body["true"], body["student"]
    assert student["reached"] == pytest.approx(t_answer, rel=1e-7)
    assert student["t"][-1] == pytest.approx(t_answer, rel=1e-7)
    assert f"{who} reaches the pulley" in student["stopped_because"]
    assert student["q"]["x"][-1] == pytest.approx(AT_PULLEY[who], rel=1e-7)
    # the true motion is drawn and compared up to the answer's end; it says where its own is
    assert true["t"] == student["t"]
    assert true["q"]["x"][-1] == pytest.approx(X0 + 0.5 * a * t_answer**2, rel=1e-7)
    assert true["reached"] == pytest.approx(t_true, rel=1e-7)
    assert f"{true_who} reaches the pulley" in true["stopped_because"]
    assert body["energy_scale"] == pytest.approx(kinetic(a, t_answer), rel=1e-7)
    assert body["energy_until"] == pytest.approx(t_answer, rel=1e-7)
    drift = true_energy(a_answer, t_answer) - true_energy(a_answer, 0.0)
    assert body["energy_change"] == pytest.approx(drift / kinetic(a, t_answer), rel=1e-6)
    assert body["parted_at"] == pytest.approx(parting_time(a, a_answer, t_answer), abs=1e-9)
    summary = body["summary"]
    assert f"Your answer's motion ends at t = {t_answer:.2f} s ({who} reaches the pulley" in summary
    if who == true_who:  # the same stop, named once
        assert f"before the true one, which gets there at t = {t_true:.2f} s:" in summary
    else:
        assert f"the true one, which ends at t = {t_true:.2f} s ({true_who} reaches" in summary
    assert f"in {t_answer:.2f} s" in summary and "5.00 s" not in summary


def test_a_right_answer_ends_with_the_true_motion(client):
    """Q_x = 0 is right: the same motion, to the same stop, said once."""
    a = acceleration()
    t_stop, _ = stop_time(a)
    body = predict(client, "0")
    assert body["correct"] is True and body["parted_at"] is None
    assert body["true"]["t"] == body["student"]["t"]
    assert body["student"]["t"][-1] == pytest.approx(t_stop, rel=1e-7)
    assert body["summary"].startswith("Your answer predicts the same motion")
    assert f"ends at t = {t_stop:.2f} s" in body["summary"]
    assert "before the true one" not in body["summary"]


def test_a_start_past_the_pulley_is_refused_and_one_at_it_ends_at_once(client):
    """As /simulate: x beyond the pulley is a 422 naming the initial state; x at the pulley,
    still rising, ends both motions at t = 0."""
    past = AT_PULLEY["mass2"] + 0.5
    r = post_predict(client, "g (m1-m2)", initial={"x": past})
    assert r.status_code == 422, r.text[:500]
    (error,) = r.json()["detail"]
    assert error["field"] == "initial" and "mass2" in error["message"]
    body = predict(client, "g (m1-m2)", initial={"x": AT_PULLEY["mass2"]})
    assert body["true"]["t"] == [0.0] and body["student"]["t"] == [0.0]
    assert "ends at t = 0.00 s" in body["summary"]


def test_masses_of_zero_are_blamed_not_the_strings_tension(client):
    """m₁ = m₂ = 0 leaves x without inertia: the 422 names the parameter, as without stops, not
    the string's tension stop (0/0 there too, but no field the student wrote)."""
    r = post_predict(client, "g (m1-m2)", parameters={"m1": 0, "m2": 0})
    assert r.status_code == 422, r.text[:500]
    (error,) = r.json()["detail"]
    assert error["field"].startswith("parameters.m") and "inertia" in error["message"]


def test_a_scene_without_stops_runs_to_t_end(client):
    """The simple pendulum has no stops: both runs go to t_end and nothing is said of an end."""
    r = client.post(
        "/api/v1/check/predict",
        json={
            "scene_id": "simple_pendulum",
            "quantity": "eom",
            "coordinate": "theta",
            "answer": "theta'' - g/l sin(theta) = 0",
            "t_end": 2,
        },
    )
    assert r.status_code == 200, r.text[:500]
    body = r.json()
    for run in (body["true"], body["student"]):
        assert run["t"][-1] == 2.0 and run["stopped_because"] is None
        assert np.allclose(np.diff(run["t"]), 1 / FPS)
    assert "ends at" not in body["summary"]
