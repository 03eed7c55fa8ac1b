"""Checker feedback a student can follow, round 4 (a student play-test of the your-turn boxes).

Every expected term is built here by hand from the textbook, not read from the engine: the
Atwood machine's ẍ = (m₁ − m₂) g / (m₁ + m₂) and −∂V/∂x = (m₁ − m₂) g; the rolling disk's
T = ½ m ẋ² + ½ (½ m R²)(ẋ/R)² and −∂V/∂x = m g sin α; the physical pendulum (a rod of length l
about its end) with I_G = m l²/12 and the torque m g (l/2) sin θ. The lines are judged by what a
student reads: the terms they typed, in the form they typed them, and nothing they did not.
"""

from __future__ import annotations

import re

import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app
from mechanics.check import check
from mechanics.derive import derivation_of_scene
from mechanics.expr import ExprError

client = TestClient(app)

m, m1, m2, ell, g, R, alpha = sp.symbols("m m1 m2 l g R alpha", positive=True)  # ell is l


def feedback(scene: str, quantity: str, answer: str, coordinate: str | None = None):
    v = check(derivation_of_scene(scene), quantity, answer, coordinate)
    assert v.correct is False, v.feedback
    return v.feedback, " ".join(v.feedback)


# --- 1. a q̈ compared as values, not as 'the term X has the coefficient Y instead of X' -------


@pytest.mark.parametrize("answer", ["-g", "g"])
def test_free_fall_for_the_atwood_acceleration_is_named_so(answer):
    lines, text = feedback("atwood_machine", "accel", answer, "x")
    right = sp.latex((m1 - m2) * g / (m1 + m2))  # (m₁ + m₂) ẍ = (m₁ − m₂) g, by hand
    assert "free-fall" in text, lines
    assert "has the coefficient" not in text and "The term" not in text, lines
    # the right value is named beside the student's own, ẍ = −g or ẍ = g as typed
    assert right in text, (right, lines)
    mine = "- g" if answer == "-g" else "g"
    assert f"Your $\\ddot{{x}} = {mine}$" in text, lines


def test_another_wrong_acceleration_reads_you_have_x_where_y_belongs():
    lines, text = feedback("atwood_machine", "accel", "g*(m1 - m2)/(m1 + 2*m2)", "x")
    assert "where" in text and "belongs" in text, lines
    assert "has the coefficient" not in text and "free-fall" not in text, lines


# --- 2. the student's own terms: no sin² rewritten, no cos(θ₁ − θ₂) expanded --------------------


def test_sin_squared_is_compared_as_typed():
    lines, text = feedback(
        "physical_pendulum", "eom", "1/3 m l^2 theta'' + m g l/2 sin(theta)^2 = 0", "theta"
    )
    theta = sp.Function("theta")(sp.Symbol("t"))
    torque = m * g * (ell / 2) * sp.sin(theta)  # the weight at the rod's centre, by hand
    assert "Extra term" not in text and "cos" not in text, lines  # 1 − cos²θ was never typed
    assert "\\sin^{2}" in text, lines  # the student's own term, named
    assert sp.latex(torque).count("sin") == 1 and "where" in text, lines
    assert len(lines) == 1, lines


@pytest.mark.parametrize(
    "quantity, answer, typed, derived",
    [
        (  # the cross term with the product of cosines the student typed
            "T",
            "1/2 (m1+m2) l1^2 theta1'^2 + 1/2 m2 l2^2 theta2'^2 "
            "+ m2 l1 l2 theta1' theta2' cos(theta1) cos(theta2)",
            r"\cos{\left(\theta_{1} \right)} \cos{\left(\theta_{2} \right)}",
            r"\cos{\left(\theta_{1} - \theta_{2} \right)}",
        ),
        (  # the lower bob's height with the angle difference typed
            "V",
            "-(m1+m2) g l1 cos(theta1) - m2 g l2 cos(theta1 - theta2)",
            r"\cos{\left(\theta_{1} - \theta_{2} \right)}",
            r"\cos{\left(\theta_{2} \right)}",
        ),
    ],
)
def test_an_angle_difference_is_not_expanded(quantity, answer, typed, derived):
    lines, text = feedback("double_pendulum", quantity, answer)
    assert typed in text and derived in text, lines
    assert "\\sin" not in text, lines  # sin θ₁ sin θ₂ is half of an expansion nobody typed
    assert "Extra term" not in text and len(lines) == 1, lines


def test_the_right_terms_typed_otherwise_are_still_right():
    # V = −(m₁ + m₂) g l₁ cos θ₁ − m₂ g l₂ cos θ₂ (heights below the pivot, by hand), typed
    # with the lower bob's term split and the first's masses multiplied out
    v = check(
        derivation_of_scene("double_pendulum"),
        "V",
        "-m1 g l1 cos(theta1) - m2 g l1 cos(theta1) - m2 g l2 cos(theta2)",
    )
    assert v.correct is True, v.feedback


# --- 3. a rotation's ½ I ω² named, not the whole answer off by a factor ------------------------


def test_a_mis_sized_disk_inertia_is_the_rotation_term():
    lines, text = feedback("rolling_disk", "T", "1/2 m x'^2 + 1/2 (m R^2)(x'/R)^2")
    assert "every term" not in text and "factor" not in text, lines
    assert "rotation" in text, lines
    assert sp.latex(m * R**2) in text and sp.latex(m * R**2 / 2) in text, lines


def test_the_disk_inertia_in_l_is_named_past_the_datum():
    # L = T − V with V = −m g x sin α (x down the slope) and the scene's own datum left out
    lines, text = feedback(
        "rolling_disk", "L", "1/2 m x'^2 + 1/2 (m R^2)(x'/R)^2 + m g x sin(alpha)"
    )
    assert "factor" not in text and "rotation" in text, lines
    assert sp.latex(m * R**2 / 2) in text and "datum" in text, lines


def test_a_single_term_off_by_a_factor_still_reads_as_one():
    x_dot = sp.Symbol("xd")
    right = sp.Rational(1, 2) * m * x_dot**2 + sp.Rational(1, 2) * (m * R**2 / 2) * (x_dot / R) ** 2
    factor = sp.simplify(m * x_dot**2 / right)  # 4/3, by hand
    lines, text = feedback("rolling_disk", "T", "m x'^2")
    assert f"factor of ${sp.latex(factor)}$" in text, lines


def test_the_centre_speed_alone_misses_the_rotation_about_g():
    lines, text = feedback("physical_pendulum", "T", "1/2 m (l/2)^2 theta'^2")
    assert "factor" not in text, lines
    assert "missing" in text and sp.latex(m * ell**2 / 12) in text, lines  # I_G of a rod


def test_the_inertia_about_the_end_in_a_sum_is_named():
    lines, text = feedback(
        "physical_pendulum", "T", "1/2 m (l/2)^2 theta'^2 + 1/2 (m l^2/3) theta'^2"
    )
    assert "factor" not in text, lines
    assert sp.latex(m * ell**2 / 3) in text and sp.latex(m * ell**2 / 12) in text, lines


# --- 4. +∂V/∂q: the conservative part with its sign flipped -----------------------------------


@pytest.mark.parametrize(
    "scene, force",
    [
        ("atwood_machine", (m1 - m2) * g),  # −∂V/∂x, from (m₁ + m₂) ẍ = (m₁ − m₂) g
        ("rolling_disk", m * g * sp.sin(alpha)),  # gravity's pull along the slope
    ],
)
def test_gravity_with_its_sign_flipped_is_named(scene, force):
    lines, text = feedback(scene, "Q", sp.sstr(-force), "x")
    assert "sign flipped" in text and "already in V" in text, lines
    assert "Extra term" not in text, lines
    right_sign, _ = feedback(scene, "Q", sp.sstr(force), "x")
    assert "sign flipped" not in " ".join(right_sign), right_sign


# --- 5. a pure number --------------------------------------------------------------------------


def test_a_bare_number_is_a_pure_number():
    lines, text = feedback("simple_pendulum", "T", "5")
    assert "The term $5$ is a pure number, not an energy" in text, lines
    assert "dimensionless" not in text, lines


# --- 6. cos 2*theta, cos w*t refused ------------------------------------------------------------


@pytest.mark.parametrize(
    "scene, answer", [("simple_pendulum", "cos 2*theta"), ("spring_mass_damper", "cos w*t")]
)
def test_a_bare_argument_times_a_factor_is_refused(scene, answer):
    with pytest.raises(ExprError) as refused:
        check(derivation_of_scene(scene), "V", answer)
    assert "parentheses" in str(refused.value), refused.value
    r = client.post("/api/v1/check", json={"scene_id": scene, "quantity": "V", "answer": answer})
    assert r.status_code == 422, r.text
    assert "answer" in r.text


def test_a_bare_coordinate_times_a_factor_and_a_quotient_still_read():
    d = derivation_of_scene("simple_pendulum")
    assert check(d, "V", "-m*g*l*cos theta").correct is True
    # cos θ/2 is cos(θ)/2 (the usual convention): half the derived V, said as a factor
    assert "factor of $\\frac{1}{2}$" in " ".join(check(d, "V", "-m*g*l*cos theta/2").feedback)
    # after a coordinate a factor is a product: cos θ·θ̇² is read, not refused
    check(d, "T", "1/2 m l^2 cos theta*theta'^2")


# --- 7. the prediction's energy yardstick: its unit and its window ----------------------------


def test_the_energy_yardstick_has_its_unit_and_its_window():
    body = {
        "scene_id": "atwood_machine",
        "quantity": "eom",
        "coordinate": "x",
        "answer": "(m1+m2) x'' = -(m1-m2) g",
    }
    r = client.post("/api/v1/check/predict", json=body)
    assert r.status_code == 200, r.text
    out = r.json()
    summary = out["summary"]
    scale = f"{out['energy_scale']:.3g} J"
    until = re.search(r"largest kinetic energy up to t = ([\d.]+) s \(([^)]*)\)", summary)
    assert until, summary
    assert until.group(2) == scale, summary
    ends = re.search(r"compared up to t = ([\d.]+) s only", summary)
    assert ends and ends.group(1) == until.group(1), summary


def test_a_full_run_has_no_window_in_the_yardstick():
    body = {"scene_id": "simple_pendulum", "quantity": "T", "answer": "m l^2 theta'^2"}
    r = client.post("/api/v1/check/predict", json=body)
    assert r.status_code == 200, r.text
    out = r.json()
    assert f"largest kinetic energy ({out['energy_scale']:.3g} J)" in out["summary"], out
