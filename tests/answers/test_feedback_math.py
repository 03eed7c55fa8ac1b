"""Feedback speaks math (LaTeX between $…$), parse errors point at the character typed, and an
equation of motion's feedback names its sign errors and misplaced terms the way T's does.

Expected positions are counted by hand in the strings below; expected terms are written out
from the textbook pendulum (m l² θ̈ + m g l sin θ = 0), not taken from the engine.
"""

from __future__ import annotations

import re

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.check import check
from mechanics.derive import derivation_of_scene
from mechanics.expr import ExprError, parse

client = TestClient(app)


def verdict(scene, quantity, answer, coordinate=None):
    return check(derivation_of_scene(scene), quantity, answer, coordinate)


def error_of(answer, quantity="T", scene="simple_pendulum", coordinate=None):
    with pytest.raises(ExprError) as info:
        verdict(scene, quantity, answer, coordinate)
    return info.value


# -- parse errors point at the right character -----------------------------------------------


@pytest.mark.parametrize(
    ("answer", "position", "says"),
    [
        # t h e t a _ +  : the '+' with nothing after it is character 6 (0-based); the term
        # goes after it, at 7 (the end)
        ("theta +", 7, "missing after '+' at the end"),
        # the student's notation is rewritten (^ -> **, spaces, θ̇ -> theta_dot) before parsing;
        # the position still counts what was typed: "m l^2 θ̇^2 +" has its '+' at 11, the
        # missing term's place at 12
        ("m l^2 θ̇^2 +", 12, "missing after '+' at the end"),
        # '(' at 0 is never closed
        ("(theta + 1", 0, "never closed"),
        # ')' at 9 closes nothing
        ("theta + 1)", 9, "without a matching"),
        # an unknown name in the middle: 'foo' starts at 2 in what was typed
        ("m*foo*l", 2, "'foo'"),
        # juxtaposed and Greek: "m g l cos θ + k" -> 'k' at 14 (θ is one character, 10)
        ("m g l cos θ + k", 14, "'k'"),
        # '**' misuse: "m***2" is m ** *2: the lone '*' at 3 has no term before it
        ("m***2", 3, "'*' needs a term"),
        ("m ** ** 2", 5, "'**' needs a term"),
        # "2*(m+)": the '+' at 4 has no term after it: it goes at 5
        ("2*(m+)", 5, "missing after '+'"),
        # '^^': the second caret at 2 (rewritten to '**') has nothing before it
        ("m^^2", 2, "needs a term"),
        # refused by the notation rewrite itself: a prime after a number, a stray character
        ("2 ' theta", 2, "prime"),
        ("θ̇ m $ l", 5, "'$'"),  # θ and its dot are two characters: 0 and 1
    ],
)
def test_parse_errors_point_at_the_character_typed(answer, position, says):
    error = error_of(answer)
    assert error.field == "answer"
    assert error.position == position, error.message
    assert says in error.message, error.message
    # the message itself shows the place, 1-based, with the text around it
    assert f"at character {position + 1}" in error.message
    assert "⟨here⟩" in error.message


def test_an_equation_split_at_equals_keeps_positions():
    # "theta'' + g/l sin(theta) = +": the right side's '+' is at 27, its missing term at 28
    text = "theta'' + g/l sin(theta) = +"
    assert text.index("=") == 25
    error = error_of(text, "eom", coordinate="theta")
    assert error.position == 28, error.message


def test_the_parser_alone_points_at_a_trailing_operator():
    """The whitelist parser itself (no student notation): Python says column 0 or the end."""
    with pytest.raises(ExprError) as info:
        parse("a + b *", {"a": 1, "b": 2}, field="f")
    assert info.value.position == 7 and "missing after '*' at the end" in info.value.message
    with pytest.raises(ExprError) as info:
        parse("a b", {"a": 1, "b": 2}, field="f")
    assert info.value.position == 2 and "operator is missing" in info.value.message


def test_api_parse_error_names_answer_and_place():
    r = client.post(
        "/api/v1/check",
        json={"scene_id": "simple_pendulum", "quantity": "T", "answer": "m l^2 theta'^2 +"},
    )
    assert r.status_code == 422
    detail = r.json()["detail"][0]
    assert detail["field"] == "answer"
    # "m l^2 theta'^2 +": '+' is character 16 counting from 1; the term goes at 17, the end
    assert "at character 17" in detail["message"]
    assert not detail["message"].startswith("syntax")


# -- feedback is math, never code -------------------------------------------------------------

WRONG = [
    ("simple_pendulum", "T", None, "m l^2 theta_dot^2"),
    ("simple_pendulum", "T", None, "m l theta_dot^2/2"),
    ("simple_pendulum", "T", None, "m l^2 theta^2/2"),
    ("simple_pendulum", "V", None, "m g l cos(theta)"),
    ("spherical_pendulum", "T", None, "m l^2 theta_dot^2/2"),
    ("cart_pendulum", "T", None, "(M+m)/2 x'^2 + M l cos(theta) x' theta' + M l^2 theta'^2/2"),
    ("simple_pendulum", "eom", "theta", "theta'' - g/l sin(theta) = 0"),
    ("simple_pendulum", "eom", "theta", "m g l sin(theta) = 0"),
    ("simple_pendulum", "accel", "theta", "g/l sin(theta) + theta_dot"),
    ("double_pendulum", "accel", "theta1", "-g/l1 sin(theta1)"),
]


@pytest.mark.parametrize(("scene", "quantity", "coordinate", "answer"), WRONG)
def test_feedback_carries_math_as_latex_not_code(scene, quantity, coordinate, answer):
    v = verdict(scene, quantity, answer, coordinate)
    assert not v.correct and v.feedback
    for line in v.feedback:
        prose = re.sub(r"\$[^$]*\$", "", line)  # what is left outside the math
        assert line.count("$") % 2 == 0, line
        assert "**" not in line and "_dot" not in prose and "*" not in prose, line
        assert "(t)" not in line and "Derivative" not in line, line


# -- equations of motion: sign errors, misplaced terms, scaling, units -----------------------


def test_eom_sign_error_is_named_in_the_students_own_scaling():
    """θ̈ − g/l sin θ = 0: the derived equation divided by m l², with one sign flipped."""
    v = verdict("simple_pendulum", "eom", "theta'' - g/l sin(theta) = 0", "theta")
    assert not v.correct
    text = " ".join(v.feedback)
    assert "Sign error in the" in text
    assert r"\frac{g \sin{\left(\theta \right)}}{l}" in text  # g/l sin θ, the student's term
    assert "not an energy" not in text and "units" not in text  # 1/s² is right for this scaling
    assert len(v.feedback) <= 2, v.feedback


def test_eom_term_carried_across_equals_with_its_sign():
    v = verdict("simple_pendulum", "eom", "m l^2 theta_ddot = m g l sin(theta)", "theta")
    assert not v.correct
    assert any("Sign error" in f and "across '='" in f for f in v.feedback), v.feedback


@pytest.mark.parametrize(
    "answer",
    [
        "m l^2 theta_ddot + m g l sin(theta) = 0",  # as derived
        "theta_ddot + g/l sin(theta) = 0",  # divided by m l²
        "m l^2 theta_ddot = -m g l sin(theta)",  # a term on the other side
        "-2 m l theta_ddot = 2 m g sin(theta)",  # times −2/l, rearranged
    ],
)
def test_eom_scaled_or_rearranged_is_correct(answer):
    assert verdict("simple_pendulum", "eom", answer, "theta").correct


def test_eom_units_are_those_of_the_students_equation():
    """A velocity term in θ̈ + g/l sin θ = 0 has units 1/s, the rest 1/s²."""
    v = verdict("simple_pendulum", "eom", "theta_ddot + g/l sin(theta) + theta_dot = 0", "theta")
    assert not v.correct
    units = [f for f in v.feedback if "units" in f]
    assert units and all("1/s" in f and "1/s²" in f for f in units), v.feedback
    assert not any("energy" in f for f in v.feedback), v.feedback


def test_eom_of_the_other_coordinate_is_named():
    """The double pendulum's θ₂ equation (hand-written, Taylor eq. 11.41 form) typed for θ₁."""
    theta2 = (
        "l2 theta2'' + l1 cos(theta1 - theta2) theta1'' - l1 sin(theta1 - theta2) theta1'^2"
        " + g sin(theta2) = 0"
    )
    v = verdict("double_pendulum", "eom", theta2, "theta1")
    assert not v.correct
    assert any(r"equation of motion for $\theta_{2}$" in f for f in v.feedback), v.feedback
    assert verdict("double_pendulum", "eom", theta2, "theta2").correct


def test_accel_may_be_written_with_its_left_side():
    assert verdict("simple_pendulum", "accel", "theta'' = -g/l sin(theta)", "theta").correct
    error = error_of("theta_dot = -g/l sin(theta)", "accel", coordinate="theta")
    assert "theta_ddot = ..." in error.message and error.position == 10


def test_a_term_is_named_as_written_not_in_expanded_pieces():
    """The double pendulum's coupling term m₂ l₁ l₂ cos(θ₁ − θ₂) θ̇₁ θ̇₂ with its sign flipped is
    one sign error in that term, not two in cos θ₁ cos θ₂ and sin θ₁ sin θ₂ (Taylor eq. 11.41)."""
    v = verdict(
        "double_pendulum",
        "T",
        "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
        " - m2 l1 l2 cos(theta1 - theta2) theta1' theta2'",
    )
    assert not v.correct
    assert len(v.feedback) == 1, v.feedback
    assert "Sign error in the" in v.feedback[0]
    assert r"\cos{\left(\theta_{1} - \theta_{2} \right)}" in v.feedback[0]


def test_eom_terms_carried_across_are_each_named():
    """(m₁+m₂) l₁ θ̈₁ + m₂ l₂ cos(θ₁−θ₂) θ̈₂ = m₂ l₂ sin(θ₁−θ₂) θ̇₂² + (m₁+m₂) g sin θ₁: both
    right-hand terms should have changed sign when moved."""
    v = verdict(
        "double_pendulum",
        "eom",
        "(m1+m2) l1 theta1'' + m2 l2 cos(theta1-theta2) theta2''"
        " = m2 l2 sin(theta1-theta2) theta2'^2 + (m1+m2) g sin(theta1)",
        "theta1",
    )
    moved = [f for f in v.feedback if "carried across '='" in f]
    assert len(moved) == 2, v.feedback


def test_a_power_of_a_sum_gets_one_line_not_one_per_expanded_term():
    """(θ + θ̇ + m + 1)⁸ expands to 165 monomials: the feedback is about the term as written."""
    v = verdict("simple_pendulum", "T", "(theta + theta_dot + m + 1)^8")
    assert not v.correct
    assert 1 <= len(v.feedback) <= 5, v.feedback
    assert any("mixes units" in f and r"\right)^{8}" in f for f in v.feedback), v.feedback
