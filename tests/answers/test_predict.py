"""What a student's answer predicts (POST /api/v1/check/predict): the student's model integrated
beside the true one.

Every expectation is computed here by hand: the pendulum's equations written out
(θ̈ = −g/l sin θ, and the wrong ones the answers stand for) and integrated with the test's own
DOP853 (tests/support/independent.py) or with a closed form of the energy balance.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from fastapi.testclient import TestClient
from independent import own_run

from app.main import app

client = TestClient(app)

# simple_pendulum's defaults, from its scene file: m = 1, l = 1, g = 9.81, θ(0) = 2, θ̇(0) = 0
M, L, G, THETA0 = 1.0, 1.0, 9.81, 2.0


def predict(answer, quantity="eom", coordinate="theta", scene="simple_pendulum", **extra):
    body = {"scene_id": scene, "quantity": quantity, "answer": answer, **extra}
    if coordinate is not None:
        body["coordinate"] = coordinate
    return client.post("/api/v1/check/predict", json=body)


def pendulum(accel):
    """The test's own run of θ̈ = accel(θ, θ̇) on the API's sample times."""

    def run(t):
        sol = own_run(lambda _, y: [y[1], accel(y[0], y[1])], [THETA0, 0.0], np.asarray(t))
        return sol.y[0], sol.y[1]

    return run


def energy(theta, theta_dot):
    """The true E = ½ m l² θ̇² − m g l cos θ of the pendulum."""
    return 0.5 * M * L**2 * theta_dot**2 - M * G * L * np.cos(theta)


def test_a_sign_error_is_integrated_as_written():
    """θ'' − g/l sin θ = 0 is θ̈ = +g/l sin θ: the bob falls away from the bottom."""
    r = predict("theta'' - g/l sin(theta) = 0")
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["correct"] is False
    student, true = body["student"], body["true"]
    theta, _ = pendulum(lambda th, _: +G / L * math.sin(th))(student["t"])
    assert np.max(np.abs(np.array(student["q"]["theta"]) - theta)) < 1e-5
    theta_true, _ = pendulum(lambda th, _: -G / L * math.sin(th))(true["t"])
    assert np.max(np.abs(np.array(true["q"]["theta"]) - theta_true)) < 1e-5
    # the bob's drawing position is (l sin θ, −l cos θ)
    x = np.array(student["positions"]["bob"]["x"])
    assert np.max(np.abs(x - L * np.sin(theta))) < 1e-5
    # they part: the two θ differ by the rule's 2 % of the scene's size soon after the start
    assert body["parted_at"] is not None and 0 < body["parted_at"] < 0.5
    assert "2%" in body["parting_rule"]
    assert "Sign error" in body["blamed"] and r"\sin" in body["blamed"]
    assert "parts visibly" in body["summary"]


def test_anti_damping_creates_energy_and_damping_destroys_it():
    """θ̈ = −g/l sin θ ± c θ̇: dE/dt = ± c m l² θ̇², so the true energy grows or falls, by
    exactly what the test's own run of the same equation says."""
    c = 0.5
    for sign, answer in ((+1, "-g/l sin(theta) + 0.5 theta_dot"), (-1, "-g/l sin θ - 0.5 θ'")):
        r = predict(answer, quantity="accel", t_end=3)
        assert r.status_code == 200, r.text
        body = r.json()
        t = body["student"]["t"]
        theta, theta_dot = pendulum(lambda th, om, s=sign: -G / L * math.sin(th) + s * c * om)(t)
        theta_t, theta_dot_t = pendulum(lambda th, _: -G / L * math.sin(th))(t)
        scale = np.max(0.5 * M * L**2 * theta_dot_t**2)  # the true run's largest T
        gained = (energy(theta[-1], theta_dot[-1]) - energy(THETA0, 0.0)) / scale
        assert math.copysign(1, body["energy_change"]) == sign
        assert body["energy_change"] == pytest.approx(gained, rel=1e-4, abs=1e-6)
        assert body["energy_scale"] == pytest.approx(scale, rel=1e-4)
        assert ("creates" if sign > 0 else "destroys") in body["summary"]


def test_a_wrong_kinetic_energy_gives_its_own_lagrange_equation():
    """T' = m l² θ̇² (twice the truth): Lagrange gives 2 m l² θ̈ + m g l sin θ = 0."""
    r = predict("m l^2 theta'^2", quantity="T", coordinate=None)
    assert r.status_code == 200, r.text
    student = r.json()["student"]
    theta, _ = pendulum(lambda th, _: -G / (2 * L) * math.sin(th))(student["t"])
    assert np.max(np.abs(np.array(student["q"]["theta"]) - theta)) < 1e-5


@pytest.mark.parametrize(
    ("quantity", "coordinate", "answer"),
    [
        ("eom", "theta", "m l^2 theta'' = -m g l sin(theta)"),
        ("accel", "theta", "-g/l sin θ"),
        ("V", None, "m g l (1 - cos θ)"),  # another datum: the same motion
        ("T", None, "1/2 m l^2 θ'^2"),
    ],
)
def test_a_right_answer_predicts_no_parting(quantity, coordinate, answer):
    body = predict(answer, quantity=quantity, coordinate=coordinate).json()
    assert body["correct"] is True
    assert body["parted_at"] is None
    assert abs(body["energy_change_max"]) < 1e-6
    gap = np.array(body["student"]["q"]["theta"]) - np.array(body["true"]["q"]["theta"])
    assert np.max(np.abs(gap)) < 1e-6
    assert body["summary"].startswith("Your answer predicts the same motion")


@pytest.mark.parametrize(
    ("answer", "extra", "says"),
    [
        ("m g l sin(theta) = 0", {}, "no acceleration"),  # no θ̈ at all
        # θ̈'s coefficient (θ − 2) vanishes at the initial θ = 2
        ("(theta - 2) theta'' + g/l sin(theta) = 0", {}, "not determined"),
        ("theta''^2 + g/l sin(theta) = 0", {}, "non-linearly"),
        ("theta'' + g/l sin(theta) +", {}, "at character"),
        ("theta_ddot/theta_dot + g/l sin(theta)", {}, "divides by zero"),  # θ̇(0) = 0
        ("m l^2 theta''^2/2", {"quantity": "L", "coordinate": None}, "higher order"),
    ],
)
def test_answers_that_give_no_motion_are_422_naming_answer(answer, extra, says):
    r = predict(answer, **{"quantity": "eom", "coordinate": "theta", **extra})
    assert r.status_code == 422, r.text
    detail = r.json()["detail"][0]
    assert detail["field"] == "answer" and says in detail["message"], detail


def test_bad_overrides_and_quantities_are_422_naming_the_field():
    r = predict("-g/l sin θ", quantity="accel", initial={"phi": 1.0})
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "initial.phi"
    r = predict("m l^2 θ'", quantity="momentum")
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "quantity"
    r = predict("-g/l sin θ", quantity="accel", t_end=100)
    assert r.status_code == 422 and "t_end" in r.json()["detail"][0]["field"]


@pytest.mark.parametrize(
    "answer",
    [
        "theta_dot^64",  # from θ̇ = 10: 1e64 rad/s², blows up at once
        "exp(exp(exp(theta_dot)))",
        "theta_dot^99",  # past the parser's exponent limit
        "1/(theta - 2)",  # singular at the initial state
    ],
)
def test_huge_answers_stay_bounded(answer):
    started = time.monotonic()
    r = predict(answer, quantity="accel", initial={"theta_dot": 10.0})
    assert time.monotonic() - started < 20
    assert r.status_code in (200, 422, 503), r.text
    if r.status_code == 200:
        student = r.json()["student"]
        assert student["blew_up_at"] is not None and student["stopped_because"]
        assert "blows up" in r.json()["summary"]
    else:
        assert r.json()["detail"][0]["field"] == "answer"


def test_double_pendulum_wrong_coupling_sign_parts_and_is_blamed():
    """T with the coupling term's sign flipped; the right T predicts the true motion."""
    right = (
        "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
        " + m2 l1 l2 cos(theta1 - theta2) theta1' theta2'"
    )
    wrong = right.replace("+ m2 l1 l2", "- m2 l1 l2")
    body = predict(wrong, quantity="T", coordinate=None, scene="double_pendulum", t_end=2).json()
    assert body["parted_at"] is not None
    assert "Sign error" in body["blamed"]
    ok = predict(right, quantity="T", coordinate=None, scene="double_pendulum", t_end=2).json()
    assert ok["parted_at"] is None


def test_openapi_documents_the_prediction_and_its_errors_in_the_one_shape():
    document = client.get("/openapi.json").json()
    operation = document["paths"]["/api/v1/check/predict"]["post"]
    ref = {"$ref": "#/components/schemas/ValidationErrors"}
    for status in ("404", "413", "422", "503"):
        assert operation["responses"][status]["content"]["application/json"]["schema"] == ref
    response = document["components"]["schemas"]["PredictResponse"]["properties"]
    assert {"true", "student", "parted_at", "energy_change", "summary"} <= set(response)


def test_a_posted_scene_predicts_like_the_built_in_one():
    spec = client.get("/api/v1/scenes/simple_pendulum").json()["spec"]
    body = {"scene": spec, "quantity": "accel", "coordinate": "theta", "answer": "g/l sin θ"}
    posted = client.post("/api/v1/check/predict", json=body)
    assert posted.status_code == 200, posted.text
    built_in = predict("g/l sin θ", quantity="accel").json()
    assert posted.json()["parted_at"] == built_in["parted_at"] is not None
    assert posted.json()["student"]["q"] == built_in["student"]["q"]


def test_a_small_energy_share_is_not_printed_as_zero_percent():
    from mechanics.predict import _pct

    assert _pct(0.004) == "0.4%" and _pct(0.0123) == "1.2%"
    assert _pct(0.41) == "41%" and _pct(0.1) == "10%"
    assert "0%" not in _pct(0.001)
