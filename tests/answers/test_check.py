"""Checking a student's answer: equivalent forms pass, typical mistakes get pointed feedback.

The "correct" answers here are written out by hand from the textbook, not taken from the engine.
"""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.answers import to_convention
from mechanics.check import check
from mechanics.derive import derivation_of_scene
from mechanics.expr import ExprError

client = TestClient(app)


def verdict(scene, quantity, answer, coordinate=None):
    return check(derivation_of_scene(scene), quantity, answer, coordinate)


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer"),
    [
        ("simple_pendulum", "T", None, "1/2 m l^2 theta'^2"),
        ("simple_pendulum", "T", None, "0.5*m*(l*thetadot)**2"),
        ("simple_pendulum", "T", None, "m l^2 θ̇^2 / 2"),
        ("simple_pendulum", "V", None, "-m g l cos θ"),
        ("simple_pendulum", "V", None, "m*g*l*(1 - cos(theta))"),  # another datum
        ("simple_pendulum", "L", None, "m l^2 dtheta^2/2 + mgl cos(theta)"),
        ("simple_pendulum", "eom", "theta", "theta'' + (g/l) sin(theta) = 0"),
        ("simple_pendulum", "eom", "theta", "m l^2 theta_ddot = -m g l sin(theta)"),
        ("simple_pendulum", "accel", "theta", "-g/l*sin(theta)"),
        ("simple_pendulum", "momentum", "theta", "m l^2 theta_dot"),
        # sin² written as 1 − cos²: the same T
        ("spherical_pendulum", "T", None, "m l^2/2 (theta_dot^2 + (1 - cos(theta)^2) phi_dot^2)"),
        (
            "double_pendulum",
            "T",
            None,
            "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
            " + m2 l1 l2 (cos theta1 cos theta2 + sin theta1 sin theta2) theta1' theta2'",
        ),
        ("atwood_machine", "accel", "x", "(m1 - m2) g / (m1 + m2)"),
        ("spring_mass_damper", "Q", "x", "F0 cos(w t) - c x_dot"),
        ("cart_pendulum", "eom", "theta", "l theta_ddot + cos(theta) x_ddot + g sin(theta) = 0"),
        ("central_force", "momentum", "theta", "m r^2 theta_dot"),
    ],
)
def test_equivalent_forms_are_accepted(scene, quantity, coordinate, answer):
    v = verdict(scene, quantity, answer, coordinate)
    assert v.correct, v.feedback


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer", "says"),
    [
        ("simple_pendulum", "T", None, "m l^2 theta_dot^2", "factor of $2$"),
        ("simple_pendulum", "V", None, "m g l cos(theta)", "Sign error"),
        ("spherical_pendulum", "T", None, "m l^2 theta_dot^2/2", "Missing term"),
        ("spherical_pendulum", "T", None, "m l^2 theta_dot^2/2", r"comes from $\dot{\phi}$"),
        ("simple_pendulum", "T", None, "m l^2 theta^2/2", r"mixed up $\theta$ and $\dot{\theta}$"),
        ("simple_pendulum", "T", None, "m l theta_dot^2/2", "not an energy"),
        (
            "double_pendulum",
            "T",
            None,
            "(m1+m2)/2 l1^2 theta1_dot^2 + m1/2 l2^2 theta2_dot^2"
            " + m2 l1 l2 cos(theta1 - theta2) theta1_dot theta2_dot",
            "coefficient",
        ),
        ("atwood_machine", "accel", "x", "(m2 - m1) g / (m1 + m2)", "Sign error"),
        (
            "cart_pendulum",
            "eom",
            "x",
            "(M+m) x_ddot + m l cos(theta) theta_ddot = F cos(w t)",
            "Missing term",
        ),
        ("simple_pendulum", "eom", "theta", "m g l sin(theta) = 0", "acceleration"),
        ("simple_pendulum", "V", None, "-m g l cos(theta) + m theta_dot", "not an energy"),
    ],
)
def test_typical_mistakes_get_feedback_that_points_at_them(
    scene, quantity, coordinate, answer, says
):
    v = verdict(scene, quantity, answer, coordinate)
    assert not v.correct
    assert any(says in f for f in v.feedback), v.feedback


def test_swapped_masses_are_named():
    """The bob's mass m put where the cart's M belongs, and vice versa."""
    v = verdict("cart_pendulum", "T", "(M+m)/2 x'^2 + M l cos(theta) x' theta' + M l^2 theta'^2/2")
    assert not v.correct
    assert any("$M$ and $m$ are swapped" in f for f in v.feedback), v.feedback


def test_wrong_spring_constant_is_pointed_at():
    v = verdict("coupled_oscillators", "V", "k x1^2/2 + k12 (x2 - x1)^2/2 + k12 x2^2/2")
    assert not v.correct
    assert any("coefficient" in f and "k_{12}" in f for f in v.feedback), v.feedback


def test_student_notation_is_rewritten_to_the_convention():
    coords, known = ["theta"], ["theta", "theta_dot", "theta_ddot", "m", "l", "g", "t"]
    assert to_convention("2m l^2 θ'", coords, known) == "2 * m * l ** 2 * theta_dot"
    assert to_convention("mgl cos θ", coords, known) == "m * g * l * cos ( theta )"
    assert to_convention("thetaddot + dtheta", coords, known) == "theta_ddot + theta_dot"


@pytest.mark.parametrize(
    "answer",
    [
        "__import__('os').system('ls')",
        "m.__class__",
        "lambda: 1",
        "9^9^9^9",
        "m;g",
        "x" * 3000,
        "(" * 500 + "m" + ")" * 500,
    ],
)
def test_hostile_answers_are_refused(answer):
    with pytest.raises(ExprError):
        verdict("simple_pendulum", "T", answer)


def test_api_verdict_reveal_and_errors():
    r = client.post(
        "/api/v1/check",
        json={
            "scene_id": "simple_pendulum",
            "quantity": "T",
            "answer": "m l^2 theta_dot^2",
            "reveal": True,
        },
    )
    assert r.status_code == 200
    body = r.json()
    assert body["correct"] is False and "expected_latex" in body
    assert r"\dot{\theta}" in body["answer_latex"]
    hidden = client.post(
        "/api/v1/check", json={"scene_id": "simple_pendulum", "quantity": "T", "answer": "m"}
    ).json()
    assert "expected_latex" not in hidden
    bad = client.post(
        "/api/v1/check",
        json={
            "scene_id": "simple_pendulum",
            "quantity": "eom",
            "answer": "theta_ddot",
            "coordinate": "phi",
        },
    )
    assert bad.status_code == 422 and bad.json()["detail"][0]["field"] == "coordinate"
    unknown = client.post(
        "/api/v1/check", json={"scene_id": "simple_pendulum", "quantity": "T", "answer": "m v^2/2"}
    )
    assert unknown.status_code == 422 and "'v'" in unknown.json()["detail"][0]["message"]
    assert client.get("/healthz").status_code == 200
