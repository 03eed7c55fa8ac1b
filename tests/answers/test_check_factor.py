"""An equation of motion times a factor of the state, and the parse messages a student meets.

The equations are derived here by hand with sympy's own LagrangesMethod (never the engine's),
and every error position is counted by hand on the text as typed (0-based).
"""

from __future__ import annotations

import tomllib
from importlib.resources import files

import pytest
import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols

from mechanics.check import check
from mechanics.derive import derivation_of_scene, derive_model
from mechanics.expr import ExprError, to_plain


def verdict(scene: str, quantity: str, answer: str, coordinate: str | None = None):
    return check(derivation_of_scene(scene), quantity, answer, coordinate)


def refusal(scene: str, quantity: str, answer: str, coordinate: str | None = None) -> ExprError:
    with pytest.raises(ExprError) as caught:
        verdict(scene, quantity, answer, coordinate)
    return caught.value


def cone_phi_equation() -> tuple[sp.Expr, sp.Symbol, sp.Symbol]:
    """The cone's φ equation by hand: x = r cos φ, z = −r sin φ, height r cot α."""
    r, phi = dynamicsymbols("r phi")
    m, g, alpha = sp.symbols("m g alpha", positive=True)
    x, y, z = r * sp.cos(phi), r * sp.cot(alpha), -r * sp.sin(phi)
    t = dynamicsymbols._t
    kinetic = m / 2 * sum(c.diff(t) ** 2 for c in (x, y, z))
    lm = LagrangesMethod(sp.simplify(kinetic - m * g * y), [r, phi])
    return sp.simplify(lm.form_lagranges_equations()[1]), m, r


def test_cone_phi_equation_over_m_r_is_accepted_and_says_why():
    by_hand, m, r = cone_phi_equation()
    t = dynamicsymbols._t
    phi = dynamicsymbols("phi")
    typed = r * phi.diff(t, 2) + 2 * r.diff(t) * phi.diff(t)
    assert sp.simplify(by_hand / (m * r) - typed) == 0  # the answer is the hand equation / (m r)
    v = verdict("particle_in_cone", "eom", "r phi'' + 2 r' phi' = 0", "phi")
    assert v.correct is True, v.feedback
    text = " ".join(v.feedback)
    assert "never zero" in text and "says nothing" not in text, v.feedback
    assert "\\frac{1}{m r}" in text, v.feedback


def test_a_sign_error_under_a_state_factor_is_named_after_dividing_it_out():
    v = verdict("particle_in_cone", "eom", "r phi'' - 2 r' phi' = 0", "phi")
    assert v.correct is False
    assert len(v.feedback) == 2, v.feedback
    assert v.feedback[0].startswith("Read as the derived equation multiplied by"), v.feedback
    assert v.feedback[1].startswith("Sign error"), v.feedback
    assert "\\dot{r}" in v.feedback[1] and "Missing term" not in " ".join(v.feedback)


def test_without_a_declared_positive_r_the_factor_may_vanish():
    """The same scene with r merely real: 1/(m r) is not provably finite and non-zero, so the
    cautious verdict stays, with a sentence that is true (may be zero)."""
    doc = tomllib.loads(files("mechanics.scenes").joinpath("particle_in_cone.toml").read_text())
    doc.pop("positive_coordinates")
    doc.pop("stops")
    v = check(derive_model(doc), "eom", "r phi'' + 2 r' phi' = 0", "phi")
    assert v.correct is False
    assert "may be zero" in " ".join(v.feedback), v.feedback


def double_pendulum_theta2() -> tuple[sp.Expr, sp.Symbol]:
    th1, th2 = dynamicsymbols("theta1 theta2")
    m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g", positive=True)
    t = dynamicsymbols._t
    x1, y1 = l1 * sp.sin(th1), -l1 * sp.cos(th1)
    x2, y2 = x1 + l2 * sp.sin(th2), y1 - l2 * sp.cos(th2)
    kinetic = m1 / 2 * (x1.diff(t) ** 2 + y1.diff(t) ** 2)
    kinetic += m2 / 2 * (x2.diff(t) ** 2 + y2.diff(t) ** 2)
    lm = LagrangesMethod(kinetic - g * (m1 * y1 + m2 * y2), [th1, th2])
    return lm.form_lagranges_equations()[1], th1


def typed(expr: sp.Expr) -> str:
    """A hand-built expression in the answer notation (theta1' for θ̇₁)."""
    t = dynamicsymbols._t
    names = {}
    for q in dynamicsymbols("theta1 theta2"):
        names[q.diff(t, 2)] = sp.Symbol(f"{q.name}_ddot")
        names[q.diff(t)] = sp.Symbol(f"{q.name}_dot")
    plain = to_plain(sp.expand(expr).subs(names))
    return plain.replace("(t)", "")


def test_double_pendulum_times_two_plus_sin_squared_is_accepted():
    equation, th1 = double_pendulum_theta2()
    v = verdict(
        "double_pendulum", "eom", typed((2 + sp.sin(th1) ** 2) * equation) + " = 0", "theta2"
    )
    assert v.correct is True, v.feedback
    assert "never zero" in v.feedback[0], v.feedback


def test_double_pendulum_times_cos_is_not_accepted_and_says_may_be_zero():
    equation, th1 = double_pendulum_theta2()
    v = verdict("double_pendulum", "eom", typed(sp.cos(th1) * equation) + " = 0", "theta2")
    assert v.correct is False
    text = " ".join(v.feedback)
    assert "may be zero" in text and "\\cos" in text, v.feedback


# -- parse messages: positions counted by hand -------------------------------------------------
def test_a_misspelt_coordinate_before_a_prime_gets_did_you_mean():
    error = refusal("double_pendulum", "T", "1/2 m1 l1^2 thetta1'^2")
    assert "unknown name 'thetta1'" in error.message and "did you mean 'theta1'" in error.message
    assert error.position == 12  # "1/2 m1 l1^2 " is 12 characters


def test_a_name_of_another_scene_before_a_prime_lists_the_coordinates():
    error = refusal("rolling_disk", "T", "3/4 m (R theta')^2")
    assert "'theta' is not a coordinate of this scene; its coordinates are x" in error.message
    assert error.position == 9


def test_a_parameter_before_a_prime_is_named_a_parameter_not_a_coordinate():
    error = refusal("double_pendulum", "T", "m1' + theta1'")
    assert "'m1' is not a coordinate" in error.message and "theta1, theta2" in error.message
    assert error.position == 0


def test_two_equals_signs_say_an_equation_has_one():
    error = refusal("double_pendulum", "eom", "a = b = c", "theta1")
    assert "an equation has one '='" in error.message and "belongs only" not in error.message
    assert error.position == 6  # the second '='


def test_d_dt_without_parentheses_points_where_the_parenthesis_goes():
    error = refusal("particle_in_cone", "T", "1/2 m ((d/dt r)^2/sin(alpha)^2 + r^2 (d/dt phi)^2)")
    assert "d/dt needs its expression in parentheses" in error.message
    assert error.position == 13  # the r after "d/dt ", where '(' goes


def test_an_unclosed_parenthesis_is_pointed_at():
    error = refusal("particle_in_cone", "T", "1/2 m ((r')^2 + r^2")
    assert "never closed" in error.message
    assert error.position == 6  # the first '(': the second one is closed after r'


@pytest.mark.parametrize(
    ("answer", "at", "depth"),
    [("exp(exp(exp(exp(theta1))))", 0, 4), ("m1 + exp(2*exp(exp(theta1)))", 5, 3)],
)
def test_nested_exponentials_point_at_the_whole_nest_and_count_it(answer, at, depth):
    error = refusal("double_pendulum", "T", answer)
    assert error.position == at
    assert f"{depth} exponentials nested one inside another" in error.message
    assert "at most 2" in error.message


def test_two_nested_exponentials_are_still_read():
    v = verdict("double_pendulum", "T", "exp(exp(theta1))")
    assert v.correct is False  # read and judged, not refused
