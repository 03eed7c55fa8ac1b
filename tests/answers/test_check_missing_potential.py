"""A potential energy left out is named as missing, not as an approximation (issue 23, 7a).

`L = ½ m l² θ̇²` for a pendulum was called "the small-angle approximation (cos θ ≈ 1)" and the
prediction view repeated that cause; it is T alone, with the weight's V = −m g l cos θ missing.
Each answer below is the scene's result written by hand with some or all of V left out (or, as
a control, with V kept in a true small-angle form, or wrong in some other way), on several
scenes and for V, L, an equation of motion and q̈; and T with V written into it (T − V, T + V).

Results by hand from the scene files (angles from the downward vertical):
- simple pendulum: T = ½ m l² θ̇², V = −m g l cos θ, m l² θ̈ + m g l sin θ = 0;
- double pendulum: V = −(m₁ + m₂) g l₁ cos θ₁ − m₂ g l₂ cos θ₂, where bob₂'s weight gives
  −m₂ g (l₁ cos θ₁ + l₂ cos θ₂) and bob₁'s −m₁ g l₁ cos θ₁;
- cart pendulum: T = ½ (M + m) ẋ² + m l cos θ ẋ θ̇ + ½ m l² θ̇², V = −m g l cos θ; with V gone,
  l θ̈ + cos θ ẍ = 0 and (M + m) ẍ + m l cos θ θ̈ − m l sin θ θ̇² = F cos ωt give
  ẍ = (F cos ωt + m l sin θ θ̇²)/(M + m sin²θ);
- bead on a hoop: T = ½ m R² (θ̇² + Ω² sin²θ), V = −m g R cos θ;
- particle in a cone: T = ½ m (ṙ²/sin²α + r² φ̇²), V = m g r cot α; with V gone,
  r̈ = r φ̇² sin²α;
- spring–mass–damper: V = ½ k x²; elastic pendulum: V = ½ k (r − l₀)² − m g r cos θ;
- Atwood machine: T = ½ (m₁ + m₂) ẋ², V = (m₂ − m₁) g x − m₂ g l.
"""

from __future__ import annotations

import pytest
import sympy as sp

from mechanics.check import check
from mechanics.derive import derivation_of_scene
from mechanics.predict import predict

m, g, length, theta = sp.symbols("m g l theta")


def lines(scene: str, quantity: str, answer: str, coordinate: str | None = None) -> list[str]:
    v = check(derivation_of_scene(scene), quantity, answer, coordinate)
    assert v.correct is False and v.confirmed, v.feedback
    return v.feedback


ALL_OF_V = [
    ("simple_pendulum", "L", None, "1/2 m l^2 theta'^2", "weight of the bob"),
    ("simple_pendulum", "L", None, "1/2 m l^2 theta'^2 + m g l", "weight of the bob"),
    ("simple_pendulum", "V", None, "0", "weight of the bob"),
    ("simple_pendulum", "V", None, "-m g l", "weight of the bob"),
    ("simple_pendulum", "eom", "theta", "m l^2 theta'' = 0", "weight of the bob"),
    ("simple_pendulum", "eom", "theta", "theta'' = 0", "weight of the bob"),
    ("simple_pendulum", "accel", "theta", "0", "weight of the bob"),
    (
        "double_pendulum",
        "L",
        None,
        "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
        " + m2 l1 l2 cos(theta1 - theta2) theta1' theta2'",
        "weights of the bob1 and the bob2",
    ),
    (
        "double_pendulum",
        "eom",
        "theta1",
        "(m1+m2) l1^2 theta1'' + m2 l1 l2 cos(theta1 - theta2) theta2''"
        " + m2 l1 l2 sin(theta1 - theta2) theta2'^2 = 0",
        "weights of the bob1 and the bob2",
    ),
    (
        "cart_pendulum",
        "L",
        None,
        "(M+m)/2 x'^2 + m l cos(theta) x' theta' + 1/2 m l^2 theta'^2",
        "weight of the bob",
    ),
    ("cart_pendulum", "eom", "theta", "l theta'' + cos(theta) x'' = 0", "weight of the bob"),
    (
        "cart_pendulum",
        "accel",
        "x",
        "(F cos(w t) + m l sin(theta) theta'^2)/(M + m sin(theta)^2)",
        "weight of the bob",
    ),
    (
        "bead_on_hoop",
        "L",
        None,
        "1/2 m R^2 (theta'^2 + Omega^2 sin(theta)^2)",
        "weight of the bead",
    ),
    (
        "bead_on_hoop",
        "eom",
        "theta",
        "R theta'' - R Omega^2 sin(theta) cos(theta) = 0",
        "weight of the bead",
    ),
    (
        "particle_in_cone",
        "L",
        None,
        "m/2 (r'^2/sin(alpha)^2 + r^2 phi'^2)",
        "weight of the particle",
    ),
    ("particle_in_cone", "accel", "r", "r phi'^2 sin(alpha)^2", "weight of the particle"),
    ("spring_mass_damper", "V", None, "0", "spring"),
    ("spring_mass_damper", "L", None, "1/2 m x'^2", "spring"),
    ("atwood_machine", "L", None, "(m1+m2)/2 x'^2", "weights of the mass1 and the mass2"),
]


@pytest.mark.parametrize(("scene", "quantity", "coordinate", "answer", "source"), ALL_OF_V)
def test_all_of_v_left_out_is_named_a_missing_potential(
    scene, quantity, coordinate, answer, source
):
    fb = lines(scene, quantity, answer, coordinate)
    assert "missing" in fb[-1] and source in fb[-1], fb
    assert "potential" in fb[-1], fb
    assert not any("small-angle" in line for line in fb), fb


def test_the_pendulum_lagrangian_without_v_names_v_itself():
    """The line quotes V = −m g l cos θ, the part left out, and says L = T − V."""
    (line,) = lines("simple_pendulum", "L", "1/2 m l^2 theta'^2")
    assert line.startswith("Your L is T alone"), line
    assert sp.latex(-m * g * length * sp.cos(theta)) in line, line
    assert "L = T − V" in line


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer", "left_out", "source"),
    [
        # bob2's −m₂ g l₂ cos θ₂ gone; its −m₂ g l₁ cos θ₁ share kept inside (m₁ + m₂)
        (
            "double_pendulum",
            "V",
            None,
            "-(m1+m2) g l1 cos(theta1)",
            r"- g l_{2} m_{2} \cos{\left(\theta_{2} \right)}",
            "weight of the bob2",
        ),
        (
            "double_pendulum",
            "L",
            None,
            "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
            " + m2 l1 l2 cos(theta1 - theta2) theta1' theta2' + (m1+m2) g l1 cos(theta1)",
            r"- g l_{2} m_{2} \cos{\left(\theta_{2} \right)}",
            "weight of the bob2",
        ),
        # bob2's whole weight left out: only bob1's −m₁ g l₁ cos θ₁ written
        ("double_pendulum", "V", None, "-m1 g l1 cos(theta1)", "", "weight of the bob2"),
        # the elastic pendulum's spring left out, its weight kept
        (
            "elastic_pendulum",
            "L",
            None,
            "m/2 (r'^2 + r^2 theta'^2) + m g r cos(theta)",
            "",
            "spring",
        ),
    ],
)
def test_part_of_v_left_out_is_named_by_the_force_it_comes_from(
    scene, quantity, coordinate, answer, left_out, source
):
    fb = lines(scene, quantity, answer, coordinate)
    assert len(fb) == 1 and "part of the potential energy" in fb[0], fb
    assert source in fb[0] and left_out in fb[0], fb
    assert not fb[0].startswith(("Missing term", "The term")), fb


def test_v_left_out_and_t_in_small_angle_form_are_both_said():
    """The cart pendulum's L with V gone and the cross term's cos θ ≈ 1: two causes, each
    named; the approximation is claimed for T's term only, which the answer keeps."""
    fb = lines("cart_pendulum", "L", "(M+m)/2 x'^2 + m l x' theta' + 1/2 m l^2 theta'^2")
    assert len(fb) == 2, fb
    assert fb[0].startswith("Your L is T alone") and "weight of the bob" in fb[0], fb
    assert "small-angle approximation of T" in fb[1] and r"\approx 1" in fb[1], fb


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer"),
    [
        # V kept as −m g l (1 − θ²/2): a true small-angle form, up to the datum
        ("simple_pendulum", "V", None, "m g l theta^2/2"),
        ("simple_pendulum", "L", None, "1/2 m l^2 theta'^2 - m g l theta^2/2"),
        ("simple_pendulum", "eom", "theta", "theta'' + g/l theta = 0"),
        ("bead_on_hoop", "eom", "theta", "R theta'' - R Omega^2 theta + g theta = 0"),
    ],
)
def test_a_potential_kept_in_small_angle_form_is_still_an_approximation(
    scene, quantity, coordinate, answer
):
    fb = lines(scene, quantity, answer, coordinate)
    assert any("small-angle approximation" in line for line in fb), fb
    assert not any("missing" in line for line in fb), fb


@pytest.mark.parametrize(
    ("scene", "quantity", "coordinate", "answer"),
    [
        ("simple_pendulum", "L", None, "1/2 m l^2 theta'^2 + m g l sin(theta)"),
        ("simple_pendulum", "V", None, "m g l cos(theta)"),  # V's sign, not V missing
        ("simple_pendulum", "L", None, "1/2 m l^2 theta'^2 + 2 m g l cos(theta)"),
        ("double_pendulum", "V", None, "-(m1+m2) g l1 cos(theta1) - m1 g l2 cos(theta2)"),
        ("simple_pendulum", "accel", "theta", "-g/l*cos(theta)"),
    ],
)
def test_other_wrong_answers_are_not_called_a_missing_potential(
    scene, quantity, coordinate, answer
):
    fb = lines(scene, quantity, answer, coordinate)
    assert not any("potential energy" in line and "missing" in line for line in fb), fb
    assert not any("small-angle" in line for line in fb), fb


def test_the_prediction_view_blames_the_missing_potential():
    """/check/predict's cause is the checker's first line: the missing V, not cos θ ≈ 1."""
    out = predict(derivation_of_scene("simple_pendulum"), "L", "1/2 m l^2 theta'^2")
    assert out["correct"] is False
    assert out["blamed"].startswith("Your L is T alone"), out["blamed"]
    assert "small-angle" not in out["summary"], out["summary"]
    assert "The cause: your L is T alone" in out["summary"], out["summary"]


@pytest.mark.parametrize(
    ("scene", "answer", "written", "source"),
    [
        # T − V = ½ m l² θ̇² + m g l cos θ, which is L
        ("simple_pendulum", "1/2 m l^2 theta'^2 + m g l cos(theta)", "T − V", "weight of the bob"),
        # T + V, the energy (with a datum 3 m g l along)
        (
            "simple_pendulum",
            "1/2 m l^2 theta'^2 - m g l cos(theta) + 3 m g l",
            "T + V",
            "weight of the bob",
        ),
        ("spring_mass_damper", "1/2 m x'^2 + 1/2 k x^2", "T + V", "spring"),
        (
            "double_pendulum",
            "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
            " + m2 l1 l2 cos(theta1 - theta2) theta1' theta2'"
            " - (-(m1+m2) g l1 cos(theta1) - m2 g l2 cos(theta2))",
            "T − V",
            "weights of the bob1 and the bob2",
        ),
    ],
)
def test_a_kinetic_energy_with_v_in_it_is_named_so(scene, answer, written, source):
    (line,) = lines(scene, "T", answer)
    assert line.startswith(f"Your T is {written}") and source in line, line
    assert "belongs in V" in line, line


def test_a_kinetic_energy_with_another_extra_term_is_not_called_t_with_v():
    fb = lines("simple_pendulum", "T", "1/2 m l^2 theta'^2 + m g l sin(theta)")
    assert not any(line.startswith("Your T is") for line in fb), fb


def test_a_kinetic_term_left_out_whole_is_not_a_second_order_approximation():
    """Spherical pendulum, by hand: T = ½ m l² (θ̇² + sin²θ φ̇²), V = −m g l cos θ. Without the
    φ̇² term (of fourth order at θ = 0, so the second-order Taylor polynomial loses it) the
    answer has left the azimuthal motion out; with sin θ ≈ θ it keeps it, approximated."""
    dropped = lines("spherical_pendulum", "L", "m l^2/2 theta'^2 - m g l theta^2/2")
    assert not any("small-angle" in line for line in dropped), dropped
    assert dropped[0].startswith("Missing term") and r"\dot{\phi}" in dropped[0], dropped
    kept = lines("spherical_pendulum", "L", "m l^2/2 (theta'^2 + theta^2 phi'^2) - m g l theta^2/2")
    assert len(kept) == 1 and "small-angle approximation" in kept[0], kept
