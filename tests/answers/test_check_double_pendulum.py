"""Your-turn feedback on the double pendulum names the term the student wrote, whole.

The expectations are the textbook's: with both angles from the downward vertical,
T = ½ (m₁ + m₂) l₁² θ̇₁² + ½ m₂ l₂² θ̇₂² + m₂ l₁ l₂ cos(θ₁ − θ₂) θ̇₁ θ̇₂ (|ṙ₁|² and |ṙ₂|² by hand)
and V = −(m₁ + m₂) g l₁ cos θ₁ − m₂ g l₂ cos θ₂; the student play-test's answers are built from
those pieces. The cross term used to come back split (cos θ₁ cos θ₂ …, sin θ₁ sin θ₂ …), and
its small-angle form (cos → 1) as 'missing' and 'extra' pieces.
"""

from __future__ import annotations

import pytest

from mechanics.check import check
from mechanics.derive import derivation_of_scene

SQUARES = "(m1 + m2)/2*l1**2*theta1_dot**2 + m2/2*l2**2*theta2_dot**2"
CROSS = "m2*l1*l2*cos(theta1 - theta2)*theta1_dot*theta2_dot"
V = "-(m1 + m2)*g*l1*cos(theta1) - m2*g*l2*cos(theta2)"
CROSS_LATEX = (
    r"l_{1} l_{2} m_{2} \cos{\left(\theta_{1} - \theta_{2} \right)} "
    r"\dot{\theta}_{1} \dot{\theta}_{2}"
)
HALVES = (
    r"\sin{\left(\theta_{1} \right)} \sin{\left(\theta_{2} \right)}",
    r"\cos{\left(\theta_{1} \right)} \cos{\left(\theta_{2} \right)}",
)


def feedback(quantity: str, answer: str) -> list[str]:
    v = check(derivation_of_scene("double_pendulum"), quantity, answer)
    assert v.correct is False
    return v.feedback


def as_quantity(quantity: str, kinetic: str) -> str:
    return kinetic if quantity == "T" else f"{kinetic} - ({V})"  # L = T − V


@pytest.mark.parametrize("quantity", ["T", "L"])
def test_the_right_answer_is_correct(quantity):
    v = check(
        derivation_of_scene("double_pendulum"),
        quantity,
        as_quantity(quantity, f"{SQUARES} + {CROSS}"),
    )
    assert v.correct is True, v.feedback


@pytest.mark.parametrize("quantity", ["T", "L"])
def test_a_missing_cross_term_is_named_whole(quantity):
    lines = feedback(quantity, as_quantity(quantity, SQUARES))
    assert lines[0].startswith("Missing term") and CROSS_LATEX in lines[0], lines
    assert not any(half in line for line in lines for half in HALVES), lines


@pytest.mark.parametrize("quantity", ["T", "L"])
def test_a_cross_term_with_the_sum_of_the_angles_is_named_as_written(quantity):
    lines = feedback(quantity, as_quantity(quantity, f"{SQUARES} + {CROSS.replace('-', '+')}"))
    assert len(lines) == 1, lines
    assert r"\cos{\left(\theta_{1} + \theta_{2} \right)}" in lines[0]
    assert r"\cos{\left(\theta_{1} - \theta_{2} \right)}" in lines[0]
    assert not any(half in lines[0] for half in HALVES)


@pytest.mark.parametrize(("factor", "says"), [("2", "$2$"), ("1/2", r"$\frac{1}{2}$")])
@pytest.mark.parametrize("quantity", ["T", "L"])
def test_a_factor_on_the_cross_term_is_one_line(quantity, factor, says):
    lines = feedback(quantity, as_quantity(quantity, f"{SQUARES} + {factor}*{CROSS}"))
    assert len(lines) == 1, lines
    assert CROSS_LATEX in lines[0] and f"off by a factor of {says}" in lines[0]


@pytest.mark.parametrize("quantity", ["T", "L"])
def test_the_small_angle_form_is_called_an_approximation(quantity):
    lines = feedback(quantity, as_quantity(quantity, f"{SQUARES} + m2*l1*l2*theta1_dot*theta2_dot"))
    assert "small-angle approximation" in lines[0], lines
    assert r"\cos{\left(\theta_{1} - \theta_{2} \right)} \approx 1" in lines[0]
    assert r"\theta_{1} = \theta_{2} = 0" in lines[0]
    assert not any(line.startswith(("Missing", "Extra")) for line in lines), lines


def test_a_lagrangian_small_in_every_angle_is_one_approximation():
    """cos(θ₁ − θ₂) ≈ 1 in T and cos θ ≈ 1 − θ²/2 in V (the datum dropped): the linearised L."""
    small_v = "(m1 + m2)*g*l1*theta1**2/2 + m2*g*l2*theta2**2/2"
    answer = f"{SQUARES} + m2*l1*l2*theta1_dot*theta2_dot - ({small_v})"
    lines = feedback("L", answer)
    assert len(lines) == 1 and "small-angle approximation" in lines[0], lines
    assert r"\cos{\left(\theta_{1} \right)} \approx 1 - \frac{\theta_{1}^{2}}{2}" in lines[0]


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer", "approximated"),
    [
        (
            "simple_pendulum",
            "accel",
            "theta",
            "-g/l*theta",
            r"keeps $\sin{\left(\theta \right)}$",
        ),
        ("simple_pendulum", "eom", "theta", "theta_ddot + g/l*theta = 0", r"\approx \theta"),
        ("simple_pendulum", "V", None, "m*g*l*theta**2/2", r"\approx 1 - \frac{\theta^{2}}{2}"),
    ],
)
def test_small_angle_forms_elsewhere(scene, quantity, coordinate, answer, approximated):
    v = check(derivation_of_scene(scene), quantity, answer, coordinate)
    assert v.correct is False
    assert any("small-angle approximation" in f and approximated in f for f in v.feedback), (
        v.feedback
    )


def test_a_wrong_small_angle_form_is_not_excused_as_an_approximation():
    """−g/l θ with the wrong sign is no approximation of −g/l sin θ: a sign error."""
    v = check(derivation_of_scene("simple_pendulum"), "accel", "g/l*theta", "theta")
    assert not any("small-angle" in f for f in v.feedback), v.feedback


def test_the_linearised_equation_of_motion_is_called_an_approximation():
    """θ₁'s equation, by hand from L: (m₁ + m₂) l₁² θ̈₁ + m₂ l₁ l₂ cos(θ₁ − θ₂) θ̈₂
    + m₂ l₁ l₂ sin(θ₁ − θ₂) θ̇₂² + (m₁ + m₂) g l₁ sin θ₁ = 0; to first order in θ, θ̇, θ̈ the
    θ̇₂² term goes and cos → 1, sin θ₁ → θ₁."""
    d = derivation_of_scene("double_pendulum")
    exact = (
        "(m1+m2)*l1**2*theta1_ddot + m2*l1*l2*cos(theta1-theta2)*theta2_ddot"
        " + m2*l1*l2*sin(theta1-theta2)*theta2_dot**2 + (m1+m2)*g*l1*sin(theta1) = 0"
    )
    assert check(d, "eom", exact, "theta1").correct is True
    linear = "(m1+m2)*l1**2*theta1_ddot + m2*l1*l2*theta2_ddot + (m1+m2)*g*l1*theta1 = 0"
    v = check(d, "eom", linear, "theta1")
    assert v.correct is False
    assert len(v.feedback) == 1 and "linearised equation" in v.feedback[0], v.feedback
    assert r"\theta_{1} = \theta_{2} = 0" in v.feedback[0]
    # the linearised equation with a slip in it is no approximation: the slip is named
    slipped = "(m1+m2)*l1**2*theta1_ddot + m2*l1*l2*theta2_ddot + m2*g*l1*theta1 = 0"
    assert not any("approximation" in f for f in check(d, "eom", slipped, "theta1").feedback)
