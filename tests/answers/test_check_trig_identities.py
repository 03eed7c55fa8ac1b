"""Trig identities in half and multiple angles are proved, never guessed (issue 23, item 7b).

A student who writes tan(φ/2) for sin φ/(1 + cos φ) is right, and used to read "not confirmed":
the proof refused any trig argument with a fractional multiple. Every "right" answer below is a
textbook identity applied by hand to the scene's result (T, V, q̈, an equation of motion), on
several scenes; every "wrong" one is the same identity misremembered (a sign, a factor, the
wrong half), which must never be called right and is refuted by a proof (confirmed wrong).

Expected results, by hand from each scene's file:
- simple pendulum: V = −m g l cos θ, θ̈ = −(g/l) sin θ, equation l θ̈ + g sin θ = 0;
- bead on a hoop spun at Ω: T = ½ m R² (θ̇² + Ω² sin²θ), V = −m g R cos θ;
- double pendulum: T = ½ (m₁ + m₂) l₁² θ̇₁² + ½ m₂ l₂² θ̇₂² + m₂ l₁ l₂ cos(θ₁ − θ₂) θ̇₁ θ̇₂,
  V = −(m₁ + m₂) g l₁ cos θ₁ − m₂ g l₂ cos θ₂;
- cart pendulum: θ's equation l θ̈ + cos θ ẍ + g sin θ = 0;
- particle in a cone of half-angle α: V = m g r cot α;
- spherical pendulum: T = ½ m l² (θ̇² + sin²θ φ̇²).
Identities used: sin x = 2 sin(x/2) cos(x/2) = 2 tan(x/2)/(1 + tan²(x/2)),
cos x = cos²(x/2) − sin²(x/2) = 1 − 2 sin²(x/2) = (1 − tan²(x/2))/(1 + tan²(x/2)),
sin x/(1 + cos x) = tan(x/2), cot x = (cot²(x/2) − 1)/(2 cot(x/2)),
cos x = 4 cos³(x/3) − 3 cos(x/3), sin x = 3 sin(x/3) − 4 sin³(x/3), sin²x = (1 − cos 2x)/2.
"""

from __future__ import annotations

import time

import pytest
import sympy as sp

from mechanics.check import check, zero_proof
from mechanics.derive import derivation_of_scene

#: The checker's own budget per answer is a few seconds; a proof of one identity stays well
#: inside it even on a loaded two-core machine.
SECONDS = 8.0

RIGHT = [
    ("simple_pendulum", "accel", "theta", "-g/l*tan(theta/2)*(1 + cos(theta))"),
    ("simple_pendulum", "accel", "theta", "-g/l*2*tan(theta/2)/(1 + tan(theta/2)^2)"),
    ("simple_pendulum", "accel", "theta", "-g/l*2*sin(theta/2)*cos(theta/2)"),
    ("simple_pendulum", "accel", "theta", "-g/l*(3 sin(theta/3) - 4 sin(theta/3)^3)"),
    ("simple_pendulum", "V", None, "-m g l (1 - tan(theta/2)^2)/(1 + tan(theta/2)^2)"),
    ("simple_pendulum", "V", None, "-m g l (1 - 2 sin(theta/2)^2)"),
    ("simple_pendulum", "V", None, "-m g l cos(theta/3) (4 cos(theta/3)^2 - 3)"),
    ("simple_pendulum", "eom", "theta", "l theta'' + g tan(theta/2) (1 + cos(theta)) = 0"),
    ("bead_on_hoop", "T", None, "1/2 m R^2 (theta'^2 + 4 Omega^2 sin(theta/2)^2 cos(theta/2)^2)"),
    ("bead_on_hoop", "T", None, "1/2 m R^2 (theta'^2 + Omega^2 (1 - cos(2 theta))/2)"),
    ("bead_on_hoop", "V", None, "-m g R (cos(theta/2)^2 - sin(theta/2)^2)"),
    (
        "double_pendulum",
        "T",
        None,
        "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
        " + m2 l1 l2 (1 - 2 sin((theta1 - theta2)/2)^2) theta1' theta2'",
    ),
    (
        "double_pendulum",
        "V",
        None,
        "-(m1+m2) g l1 (1 - tan(theta1/2)^2)/(1 + tan(theta1/2)^2) - m2 g l2 cos(theta2)",
    ),
    (
        "cart_pendulum",
        "eom",
        "theta",
        "l theta'' + (2 cos(theta/2)^2 - 1) x'' + 2 g sin(theta/2) cos(theta/2) = 0",
    ),
    ("particle_in_cone", "V", None, "m g r (cot(alpha/2)^2 - 1)/(2 cot(alpha/2))"),
    (
        "spherical_pendulum",
        "T",
        None,
        "m l^2/2 (theta'^2 + 4 sin(theta/2)^2 cos(theta/2)^2 phi'^2)",
    ),
]

WRONG = [
    # tan(θ/2)(1 − cos θ) is 2 sin²(θ/2) tan(θ/2), not sin θ
    ("simple_pendulum", "accel", "theta", "-g/l*tan(theta/2)*(1 - cos(theta))"),
    ("simple_pendulum", "accel", "theta", "-g/l*2*tan(theta/2)"),  # 2 tan(x/2) is not sin x
    ("simple_pendulum", "accel", "theta", "-g/l*sin(theta/2)"),
    ("simple_pendulum", "V", None, "-m g l (1 - tan(theta/2)^2)/(1 - tan(theta/2)^2)"),
    ("simple_pendulum", "V", None, "-m g l cos(theta/3) (4 cos(theta/3)^2 - 2)"),
    # 2 tan(x/2)/(1 − tan²(x/2)) is tan x
    ("simple_pendulum", "eom", "theta", "l theta'' + 2 g tan(theta/2)/(1 - tan(theta/2)^2) = 0"),
    ("bead_on_hoop", "T", None, "1/2 m R^2 (theta'^2 + 2 Omega^2 sin(theta/2)^2 cos(theta/2)^2)"),
    ("bead_on_hoop", "V", None, "-m g R (cos(theta/2)^2 + sin(theta/2)^2)"),
    (
        "double_pendulum",
        "T",
        None,
        "(m1+m2)/2 l1^2 theta1'^2 + m2/2 l2^2 theta2'^2"
        " + m2 l1 l2 (1 - 2 sin((theta1 + theta2)/2)^2) theta1' theta2'",
    ),
    ("particle_in_cone", "V", None, "m g r (cot(alpha/2)^2 + 1)/(2 cot(alpha/2))"),
]


@pytest.mark.parametrize(("scene", "quantity", "coordinate", "answer"), RIGHT)
def test_a_half_or_multiple_angle_form_of_the_result_is_proved_right(
    scene, quantity, coordinate, answer
):
    start = time.perf_counter()
    v = check(derivation_of_scene(scene), quantity, answer, coordinate)
    assert v.correct is True and v.confirmed, v.feedback
    assert time.perf_counter() - start < SECONDS


@pytest.mark.parametrize(("scene", "quantity", "coordinate", "answer"), WRONG)
def test_a_misremembered_identity_is_never_called_right(scene, quantity, coordinate, answer):
    start = time.perf_counter()
    v = check(derivation_of_scene(scene), quantity, answer, coordinate)
    assert v.correct is False, v.feedback
    assert v.confirmed, v.feedback  # refuted, not "not confirmed": a proof says it differs
    assert not any(line.startswith("Correct") for line in v.feedback), v.feedback
    assert time.perf_counter() - start < SECONDS


def test_the_renaming_of_a_half_angle_is_exact():
    """θ → 2u is a bijection: the identity holds in u exactly when in θ; a misremembered one
    stays refuted after the renaming (zero_proof answers False, not None)."""
    d = derivation_of_scene("simple_pendulum")
    (theta,) = d.model.q
    half = sp.tan(theta / 2) - sp.sin(theta) / (1 + sp.cos(theta))
    assert zero_proof(half, d.model) is True
    assert zero_proof(sp.tan(theta / 2) - sp.sin(theta) / (1 - sp.cos(theta)), d.model) is False
    # mixed denominators: θ/2 and θ/3 beside θ, renamed θ = 6u
    mixed = sp.sin(theta / 2) * sp.cos(theta / 3) - (sp.sin(5 * theta / 6) + sp.sin(theta / 6)) / 2
    assert zero_proof(mixed, d.model) is True
