"""A sign slipped inside a bracket of parameters is named in the student's own bracket
(issue 23, item 7c).

(m₁ + m₂) typed as (m₁ − m₂) used to read "the term g l₁ (m₁ + m₂) sin θ₁ has the coefficient
g l₁ (m₁ − m₂) instead of …": the derived term restated. The feedback must quote the bracket the
student typed, say which sign inside it is wrong, and never claim a slip that does not make the
answer right.

Results by hand from the scene files:
- double pendulum: T = ½ (m₁ + m₂) l₁² θ̇₁² + ½ m₂ l₂² θ̇₂² + m₂ l₁ l₂ cos(θ₁ − θ₂) θ̇₁ θ̇₂,
  V = −(m₁ + m₂) g l₁ cos θ₁ − m₂ g l₂ cos θ₂, θ₁'s equation (m₁ + m₂) l₁² θ̈₁
  + m₂ l₁ l₂ cos(θ₁ − θ₂) θ̈₂ + m₂ l₁ l₂ sin(θ₁ − θ₂) θ̇₂² + (m₁ + m₂) g l₁ sin θ₁ = 0;
- cart pendulum: T = ½ (M + m) ẋ² + m l cos θ ẋ θ̇ + ½ m l² θ̇², x's equation
  (M + m) ẍ + m l cos θ θ̈ − m l sin θ θ̇² = F cos ωt;
- Atwood machine (mass₁ at height −x, mass₂ at x − l): V = −(m₁ − m₂) g x − m₂ g l,
  (m₁ + m₂) ẍ = (m₁ − m₂) g;
- coupled oscillators (walls, k, k₁₂, k): V = ½ (k + k₁₂) x₁² + ½ (k + k₁₂) x₂² − k₁₂ x₁ x₂.
"""

from __future__ import annotations

import pytest

from mechanics.check import check
from mechanics.derive import derivation_of_scene

SQUARES = "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
CROSS = "m2 l1 l2 cos(theta1 - theta2) theta1' theta2'"
EOM1 = (
    "{inertia} l1^2 theta1'' + m2 l1 l2 cos(theta1 - theta2) theta2''"
    " + m2 l1 l2 sin(theta1 - theta2) theta2'^2 + {weight} g l1 sin(theta1) = 0"
)
M12 = ("m_{1} - m_{2}", "m_{1} + m_{2}")  # (as typed, as it should be) in LaTeX


def feedback(scene: str, quantity: str, answer: str, coordinate: str | None = None) -> list[str]:
    v = check(derivation_of_scene(scene), quantity, answer, coordinate)
    assert v.correct is False and v.confirmed, v.feedback
    return v.feedback


SLIPS = [
    # (scene, quantity, coordinate, answer, the student's bracket, the right one)
    (
        "double_pendulum",
        "T",
        None,
        f"(m1-m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2 + {CROSS}",
        *M12,
    ),
    (
        "double_pendulum",
        "V",
        None,
        "-(m1 - m2) g l1 cos(theta1) - m2 g l2 cos(theta2)",
        *M12,
    ),
    (
        "double_pendulum",
        "L",
        None,
        f"{SQUARES} + {CROSS} + (m1 - m2) g l1 cos(theta1) + m2 g l2 cos(theta2)",
        *M12,
    ),
    (
        "double_pendulum",
        "eom",
        "theta1",
        EOM1.format(inertia="(m1+m2)", weight="(m1-m2)"),
        *M12,
    ),
    (
        "double_pendulum",
        "eom",
        "theta1",
        EOM1.format(inertia="(m1+m2)", weight="(-m1+m2)"),
        "- m_{1} + m_{2}",
        "m_{1} + m_{2}",
    ),
    (
        "double_pendulum",
        "eom",
        "theta1",
        EOM1.format(inertia="(m1-m2)", weight="(m1+m2)"),
        *M12,
    ),
    (
        "cart_pendulum",
        "T",
        None,
        "(M-m)/2 x'^2 + m l x' theta' cos(theta) + 1/2 m l^2 theta'^2",
        "M - m",
        "M + m",
    ),
    (
        "cart_pendulum",
        "eom",
        "x",
        "(M-m) x'' + m l cos(theta) theta'' - m l sin(theta) theta'^2 = F cos(w t)",
        "M - m",
        "M + m",
    ),
    ("atwood_machine", "V", None, "-(m1 + m2) g x", "m_{1} + m_{2}", "m_{1} - m_{2}"),
    ("atwood_machine", "eom", "x", "(m1 + m2) x'' = (m1 + m2) g", "m_{1} + m_{2}", "m_{1} - m_{2}"),
    (
        "coupled_oscillators",
        "V",
        None,
        "(k - k12)/2 x1^2 + (k + k12)/2 x2^2 - k12 x1 x2",
        "k - k_{12}",
        "k + k_{12}",
    ),
]


@pytest.mark.parametrize(("scene", "quantity", "coordinate", "answer", "typed", "right"), SLIPS)
def test_a_sign_slip_inside_a_bracket_is_named_in_the_students_bracket(
    scene, quantity, coordinate, answer, typed, right
):
    fb = feedback(scene, quantity, answer, coordinate)
    slip = [line for line in fb if line.startswith("Sign error inside your factor")]
    assert len(slip) == 1, fb
    assert f"your factor ${typed}$" in slip[0], slip
    assert f"should be ${right}$" in slip[0], slip
    # the derived term is not restated as the coefficient the student 'should' have
    assert not any("has the coefficient" in line for line in fb), fb


def test_the_inertia_bracket_is_called_the_inertia_term():
    fb = feedback("atwood_machine", "eom", "(m1-m2) x'' = (m1-m2) g", "x")
    assert "first of your brackets" in fb[0] and "inertia term" in fb[0], fb
    assert "should be $m_{1} + m_{2}$" in fb[0], fb


def test_the_students_term_is_quoted_with_the_bracket_as_typed():
    """−(m₁ − m₂) g l₁ cos θ₁: sympy holds g l₁ (−m₁ + m₂) cos θ₁, a bracket nobody typed."""
    (line,) = feedback("double_pendulum", "V", "-(m1 - m2) g l1 cos(theta1) - m2 g l2 cos(theta2)")
    assert r"\left(m_{1} - m_{2}\right)" in line, line
    assert r"- m_{1} + m_{2}" not in line, line


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer"),
    [
        # the slip and another error: no one sign makes it right
        ("double_pendulum", "V", None, "-(m1 - m2) g l1 cos(theta1) - m1 g l2 cos(theta2)"),
        # the whole bracket's sign (a sign error of the term, named as such)
        ("double_pendulum", "V", None, "(m1 + m2) g l1 cos(theta1) - m2 g l2 cos(theta2)"),
        # a bracket with a coordinate in it is no coefficient
        (
            "double_pendulum",
            "T",
            None,
            f"{SQUARES} + m2 l1 l2 cos(theta1 + theta2) theta1' theta2'",
        ),
        ("cart_pendulum", "T", None, "(M+m)/2 x'^2 + m l x' theta' cos(theta) + m l^2 theta'^2"),
    ],
)
def test_no_slip_is_claimed_where_one_sign_does_not_make_it_right(
    scene, quantity, coordinate, answer
):
    fb = feedback(scene, quantity, answer, coordinate)
    assert not any("inside your factor" in line for line in fb), fb


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer"),
    [
        ("double_pendulum", "V", None, "-(m1 + m2) g l1 cos(theta1) - m2 g l2 cos(theta2)"),
        ("atwood_machine", "accel", "x", "(m1 - m2) g / (m1 + m2)"),
        (
            "cart_pendulum",
            "eom",
            "x",
            "(M+m) x'' + m l cos(theta) theta'' - m l sin(theta) theta'^2 = F cos(w t)",
        ),
    ],
)
def test_the_right_answer_with_brackets_stays_right(scene, quantity, coordinate, answer):
    v = check(derivation_of_scene(scene), quantity, answer, coordinate)
    assert v.correct is True, v.feedback


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer", "typed"),
    [
        # (m₁ + m₂) g l₁ sin θ₁ written out as two terms, one with its sign flipped
        (
            "double_pendulum",
            "eom",
            "theta1",
            "(m1+m2) l1^2 theta1'' + m2 l1 l2 cos(theta1 - theta2) theta2''"
            " + m2 l1 l2 sin(theta1 - theta2) theta2'^2"
            " + m1 g l1 sin(theta1) - m2 g l1 sin(theta1) = 0",
            r"- g l_{1} m_{2} \sin{\left(\theta_{1} \right)}",
        ),
        (
            "double_pendulum",
            "T",
            None,
            f"m1/2 l1^2 theta1'^2 - m2/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2 + {CROSS}",
            r"- \frac{l_{1}^{2} m_{2} \dot{\theta}_{1}^{2}}{2}",
        ),
        (
            "cart_pendulum",
            "T",
            None,
            "M/2 x'^2 - m/2 x'^2 + m l x' theta' cos(theta) + 1/2 m l^2 theta'^2",
            r"- \frac{m \dot{x}^{2}}{2}",
        ),
    ],
)
def test_a_sign_slip_in_a_written_out_coefficient_names_the_students_term(
    scene, quantity, coordinate, answer, typed
):
    fb = feedback(scene, quantity, answer, coordinate)
    assert fb[0].startswith(f"Sign error in your term ${typed}$"), fb
    assert not any("has the coefficient" in line for line in fb), fb
