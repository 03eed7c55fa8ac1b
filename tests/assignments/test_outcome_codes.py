"""One hand-written wrong answer per outcome code (issue 27): each must produce its code.

The answers are written by hand from the scenes' textbook results (simple pendulum
T = ½ m l² θ̇², V = −m g l cos θ; the cart pendulum's T = ½ (M + m) ẋ² + ½ m l² θ̇² + m l cos θ ẋ θ̇;
the damped oscillator's Q_x = F₀ cos ωt − c ẋ, ...), each broken in one known way.
"""

from __future__ import annotations

import pytest

from mechanics.assignments import grading, outcomes
from mechanics.budget import BudgetExceeded

from .support import one_part

TERMS_45 = "m*l^2*theta_dot^2*(" + "+".join(f"theta^{k}" for k in range(1, 46)) + ")"
CART_T = "(M+m)*x_dot^2/2 + m*l^2*theta_dot^2/2"

#: (expected code, scene, quantity, coordinate, the hand-written answer)
CASES = [
    ("T.correct", "simple_pendulum", "T", None, "m*l^2*theta_dot^2/2"),
    ("V.correct_up_to_constant", "simple_pendulum", "V", None, "-m*g*l*cos(theta) + 7*m*g*l"),
    (
        "T.cannot_decide",
        "simple_pendulum",
        "T",
        None,
        "m*l^2*theta_dot^2/2 + exp(-10^6*theta_dot^2)",
    ),
    (
        "T.undefined",
        "simple_pendulum",
        "T",
        None,
        "m*l^2*theta_dot^2/2/(sin(theta)^2+cos(theta)^2-1)",
    ),
    ("eom.no_acceleration", "simple_pendulum", "eom", "theta", "m*l^2 = 0"),
    (
        "eom.other_coordinate",
        "cart_pendulum",
        "eom",
        "theta",
        "(M+m)*x_ddot + m*l*cos(theta)*theta_ddot - m*l*sin(theta)*theta_dot^2 = F*cos(w*t)",
    ),
    (
        "eom.vanishing_factor",
        "simple_pendulum",
        "eom",
        "theta",
        "sin(theta)*(m*l^2*theta_ddot + m*g*l*sin(theta)) = 0",
    ),
    (
        "eom.mixed_equations",
        "double_pendulum",
        "eom",
        "theta1",
        "(m1+m2)*l1^2*theta1_ddot + m2*l1*l2*cos(theta1-theta2)*theta2_ddot"
        " + m2*l1*l2*sin(theta1-theta2)*theta2_dot^2 + (m1+m2)*g*l1*sin(theta1)"
        " + m2*l2^2*theta2_ddot + m2*l1*l2*cos(theta1-theta2)*theta1_ddot"
        " - m2*l1*l2*sin(theta1-theta2)*theta1_dot^2 + m2*g*l2*sin(theta2) = 0",
    ),
    (
        "eom.inertia_term",
        "cart_pendulum",
        "eom",
        "x",
        "M*x_ddot + m*l*cos(theta)*theta_ddot - m*l*sin(theta)*theta_dot^2 = F*cos(w*t)",
    ),
    ("accel.unsolved", "cart_pendulum", "accel", "theta", "-(g*sin(theta) + cos(theta)*x_ddot)/l"),
    ("Q.includes_potential_force", "spring_mass_damper", "Q", "x", "F0*cos(w*t) - c*x_dot - k*x"),
    (
        "L.up_to_total_derivative",
        "simple_pendulum",
        "L",
        None,
        "m*l^2*theta_dot^2/2 + m*g*l*cos(theta) + 2*theta*theta_dot",
    ),
    (
        "L.time_function",
        "simple_pendulum",
        "L",
        None,
        "m*l^2*theta_dot^2/2 + m*g*l*cos(theta) + t^2",
    ),
    ("V.shifted_datum", "spring_mass_damper", "V", None, "k*(x-L0)^2/2"),
    ("eom.small_angle", "simple_pendulum", "eom", "theta", "m*l^2*theta_ddot + m*g*l*theta = 0"),
    ("T.rounding", "simple_pendulum", "T", None, "0.4999999*m*l^2*theta_dot^2"),
    (
        "V.swapped_parameters",
        "double_pendulum",
        "V",
        None,
        "-(m1+m2)*g*l1*cos(theta1) - m1*g*l2*cos(theta2)",
    ),
    ("T.q_qdot_mixup", "simple_pendulum", "T", None, "m*l^2*theta^2/2"),
    ("T.rotation_term", "rolling_disk", "T", None, "m*x_dot^2/2 + m*x_dot^2/2"),
    ("T.negated", "simple_pendulum", "T", None, "-m*l^2*theta_dot^2/2"),
    ("T.sign_error", "cart_pendulum", "T", None, CART_T + " - m*l*cos(theta)*x_dot*theta_dot"),
    ("eom.sign_error", "spring_mass_damper", "eom", "x", "m*x_ddot + c*x_dot - k*x = F0*cos(w*t)"),
    ("T.wrong_factor", "simple_pendulum", "T", None, "m*l^2*theta_dot^2"),
    ("L.missing_potential", "simple_pendulum", "L", None, "m*l^2*theta_dot^2/2"),
    ("T.missing_term", "cart_pendulum", "T", None, CART_T),
    ("T.extra_term", "simple_pendulum", "T", None, "m*l^2*theta_dot^2/2 + m*g*l"),
    (
        "T.wrong_term",
        "double_pendulum",
        "T",
        None,
        "(m1+m2)*l1^2*theta1_dot^2/2 + m2*l2^2*theta2_dot^2/2"
        " + m1*l1*l2*cos(theta1-theta2)*theta1_dot*theta2_dot",
    ),
    ("V.wrong_units", "simple_pendulum", "V", None, "-m*g*l*cos(theta) + m"),
    (
        "T.tiny_difference",
        "cart_pendulum",
        "T",
        None,
        CART_T + " + (1+1e-13)*m*l*cos(theta)*x_dot*theta_dot",
    ),
    ("T.wrong", "simple_pendulum", "T", None, TERMS_45),
    ("T.unreadable", "simple_pendulum", "T", None, "(m*l^2*theta_dot^2/2"),
    # the pendulum's ω = √(g/l) by hand: ω² typed for ω, and f = ω/2π
    ("omega.squared", "simple_pendulum", "frequency", None, "g/l"),
    ("omega.hertz", "simple_pendulum", "frequency", None, "sqrt(g/l)/(2*pi)"),
]


@pytest.mark.parametrize(
    ("expected", "scene", "quantity", "coordinate", "answer"), CASES, ids=[c[0] for c in CASES]
)
def test_a_hand_written_answer_gets_its_code(expected, scene, quantity, coordinate, answer):
    variant = one_part(scene, quantity, coordinate)
    judged = grading.judge(variant, variant.parts[0], answer)
    assert judged.code == expected, judged.feedback


def test_every_code_in_the_table_has_its_hand_written_answer():
    """The table and the cases move together: a new kind needs its wrong answer here."""
    tested = {c[0].split(".", 1)[1] for c in CASES}
    assert tested == {row["kind"] for row in outcomes.table()}


def test_past_the_budget_is_cannot_decide_not_wrong():
    def slow(*args):
        raise BudgetExceeded("time", "checking this answer took longer than 5 s", "answer")

    variant = one_part("simple_pendulum", "T")
    judged = grading.judge(variant, variant.parts[0], "m*l^2*theta_dot^2", run=slow)
    assert (judged.code, judged.decided) == ("T.cannot_decide", False)
    assert judged.feedback[0].startswith("Cannot decide, because")


def test_codes_carry_no_parameters():
    """A code is the same for every variant: no number, no symbol of the scene in it."""
    for kind in outcomes.table():
        assert kind["kind"].replace("_", "").isalpha()


def test_the_documented_table_is_the_codes_table():
    """docs/assignments.md lists every kind, in the order they are tried."""
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[2] / "docs" / "assignments.md").read_text()
    listed = [line.split("`")[1] for line in doc.splitlines() if line.startswith("| `")]
    kinds = [row["kind"] for row in outcomes.table()]
    assert [k for k in listed if k in kinds] == kinds
