"""How a typed answer's function notation is read (a hostile play-test), and what the checker
then says.

Every expected reading is a sympy expression built here by hand from plain symbols, and every
expected verdict compares it to the scene's own V, T or Q^NC written by hand from the scene file
(the bob at l (sin θ, −cos θ) under g; the block at L0 + x on a spring of rest length L0 from the
wall). The engine's reading is only ever compared to them.
"""

from __future__ import annotations

import tomllib
from importlib.resources import files

import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app
from mechanics.answers import read_answer
from mechanics.check import check
from mechanics.derive import derivation_of_scene

client = TestClient(app)

m, g, k, c, L0, F0, w, t = sp.symbols("m g k c L0 F0 w t")
l = sp.Symbol("l")  # noqa: E741 - the pendulum length, as the scene names it
theta, theta_dot, phi_dot, x, x_dot = sp.symbols("theta theta_dot phi_dot x x_dot")

PENDULUM_V = -m * g * l * sp.cos(theta)  # by hand: the bob's height is −l cos θ
PENDULUM_EOM = "m l^2 theta'' + m g l sin theta"  # m l² θ̈ + m g l sin θ = 0, by hand
SPRING_V = k * ((L0 + x) - L0) ** 2 / 2  # the block at L0 + x, the wall at 0, rest length L0
SPRING_Q_NC = F0 * sp.cos(w * t) - c * x_dot  # the drive and the damper, by hand


def reading(scene: str, quantity: str, answer: str, coordinate: str | None = None) -> sp.Expr:
    """The engine's reading of ``answer`` in plain symbols (θ(t) -> theta, θ̇ -> theta_dot)."""
    d = derivation_of_scene(scene)
    j = None if coordinate is None else d.model.coordinate_names.index(coordinate)
    given, _ = read_answer(d, quantity, answer, j)
    plain = {value: sp.Symbol(name) for name, value in d.model.names.items()}
    return given.xreplace(plain)


def refusal(scene: str, quantity: str, answer: str, coordinate: str | None = None) -> str:
    """The message of the 422 the API gives ``answer`` (asserted to be one, on answer)."""
    body = {"scene_id": scene, "quantity": quantity, "answer": answer}
    if coordinate:
        body["coordinate"] = coordinate
    r = client.post("/api/v1/check", json=body)
    assert r.status_code == 422, r.text
    (problem,) = r.json()["detail"]
    assert set(problem) == {"field", "message"} and problem["field"] == "answer", problem
    return problem["message"]


def scene_parameters(scene: str) -> dict[sp.Symbol, sp.Rational]:
    doc = tomllib.loads(files("mechanics.scenes").joinpath(f"{scene}.toml").read_text())
    return {sp.Symbol(n): sp.Rational(str(v)) for n, v in doc["parameters"].items()}


# --- 1. sin^n(θ) is one operand: a power after it applies to sin^n θ as a whole ----------------


@pytest.mark.parametrize(
    "answer, by_hand",
    [
        ("-m g l cos^2(theta)^3", -m * g * l * sp.cos(theta) ** 6),  # was cos⁸θ
        ("-m g l cos^2(θ)^3", -m * g * l * sp.cos(theta) ** 6),
        ("-m g l cos^2(theta)^3 / cos^5(theta)", -m * g * l * sp.cos(theta)),  # was cos³θ
        ("-m g l sin^2(theta)^3 - m g l cos θ", -m * g * l * (sp.sin(theta) ** 6 + sp.cos(theta))),
        ("2 sin^3(θ)^2 m g l", 2 * m * g * l * sp.sin(theta) ** 6),
    ],
)
def test_a_function_power_then_a_power_is_the_power_of_the_power(answer, by_hand):
    read = reading("simple_pendulum", "V", answer)
    assert sp.simplify(read - by_hand) == 0, read
    v = check(derivation_of_scene("simple_pendulum"), "V", answer)
    assert v.correct is (sp.simplify(by_hand - PENDULUM_V) == 0), (v.answer_latex, v.feedback)


# --- 2. a function without parentheses, then a power or a factor that may be its argument -----


@pytest.mark.parametrize(
    "scene, quantity, coordinate, answer, alternatives",
    [
        # one rule for a power after the bare argument, with or without sin^n before it:
        # cos θ^3 is cos³θ to some and cos(θ³) to others (it was read cos³θ, cos^2 θ^3 cos⁸θ)
        ("simple_pendulum", "V", None, "-m g l cos theta^3", ("cos(theta)^3", "cos(theta^3)")),
        ("simple_pendulum", "V", None, "-m g l cos θ³", ("cos(theta)^3", "cos(theta^3)")),
        ("simple_pendulum", "V", None, "-m g l cos^1 theta^3", ("cos^1(theta)^3",)),
        ("simple_pendulum", "V", None, "-m g l cos^2 theta^3", ("cos^2(theta^3)",)),
        ("simple_pendulum", "V", None, "cos^2 theta^0.5", ("cos^2(theta)^0.5",)),
        # a number then a name: sin(2θ) to the student, sin(2)·θ to a parser (it was the latter)
        ("simple_pendulum", "V", None, "-m g l cos 2theta", ("cos(2 theta)", "cos(2) theta")),
        ("simple_pendulum", "V", None, "sin 2 theta", ("sin(2 theta)",)),
        ("simple_pendulum", "V", None, "cos^2 2 theta", ("cos^2(2 theta)",)),
        ("simple_pendulum", "V", None, "sin 2 (theta)", ("sin(2 (...))",)),
        # a parameter then a name: the drive cos(w t), read cos(w)·t before
        ("spring_mass_damper", "Q", "x", "F0 cos w t - c x'", ("cos(w t)", "cos(w) t")),
    ],
)
def test_an_argument_that_reads_two_ways_is_refused_with_both(
    scene, quantity, coordinate, answer, alternatives
):
    message = refusal(scene, quantity, answer, coordinate)
    assert "parentheses" in message and "two ways" in message, message
    for alternative in alternatives:
        assert alternative in message, message


def test_after_a_coordinate_a_factor_is_a_product_and_a_prime_its_rate():
    # the notes write sin²θ φ̇² and cos θ (1 − cos θ): products (read so before, and still)
    read = reading("spherical_pendulum", "T", "1/2 m l^2 (θ'^2 + sin^2 θ φ'^2)")
    by_hand = m * l**2 * (theta_dot**2 + sp.sin(theta) ** 2 * phi_dot**2) / 2
    assert sp.simplify(read - by_hand) == 0, read
    read = reading("simple_pendulum", "V", "-m g l cos θ (1 - cos θ)")
    assert sp.simplify(read + m * g * l * sp.cos(theta) * (1 - sp.cos(theta))) == 0, read
    # cos θ' is the cosine of θ̇ (it was refused: 'a prime must follow a coordinate name')
    read = reading("simple_pendulum", "V", "m g l θ cos θ'")
    assert sp.simplify(read - m * g * l * sp.cos(theta_dot) * theta) == 0, read
    read = reading("simple_pendulum", "V", "m g l sin^2 θ'")
    assert sp.simplify(read - m * g * l * sp.sin(theta_dot) ** 2) == 0, read


# --- 3. the refusals name what was typed -------------------------------------------------------


@pytest.mark.parametrize(
    "answer, function, inverse",
    [
        ("cos^1.0 theta", "cos", "acos"),
        ("cos^-1 theta", "cos", "acos"),
        ("cos^2 -theta", "cos", "acos"),
        ("m g l tan^x(theta)", "tan", "atan"),
        ("exp^-1 theta", "exp", None),  # no aexp: no inverse is named
    ],
)
def test_the_power_refusal_names_the_function_typed(answer, function, inverse):
    message = refusal("simple_pendulum", "V", answer)
    assert f"{function}^2(theta)" in message and f"square of {function}" in message, message
    assert "sin" not in message.replace(function, ""), message
    if inverse:
        assert f"inverse is {inverse}(" in message, message
    else:
        assert "inverse" not in message, message


@pytest.mark.parametrize(
    "factor, typed",
    [((l - 1) ** 2, "(l - 1)^2"), ((m - 1) ** 3, "(m - 1)^3 (l + 2)"), ((l - 1) ** 2, "(l-1)^2")],
)
def test_a_factor_zero_at_the_scenes_values_is_named_with_its_power(factor, typed):
    assert factor.subs(scene_parameters("simple_pendulum")) == 0  # the premise, from the file
    v = check(
        derivation_of_scene("simple_pendulum"), "eom", f"{typed} * ({PENDULUM_EOM}) = 0", "theta"
    )
    assert v.correct is False and v.confirmed is True, v.feedback
    assert f"multiplied by ${sp.latex(factor)}$, which is 0" in v.feedback[0], v.feedback


# --- 4. Q^NC plus the conservative part plus something else: both are named ------------------


@pytest.mark.parametrize(
    "scene, coordinate, answer, by_hand, V, q, nonconservative",
    [
        (
            "spring_mass_damper",
            "x",
            "-c x' + F0 cos(w t) - k (x - L0)",
            SPRING_Q_NC - k * (x - L0),
            SPRING_V,
            x,
            SPRING_Q_NC,
        ),
        (  # −k x merged into (m w² − k) x, a coefficient holding it as a summand
            "spring_mass_damper",
            "x",
            "-c x' + F0 cos(w t) + (m w^2 - k) x",
            SPRING_Q_NC + (m * w**2 - k) * x,
            SPRING_V,
            x,
            SPRING_Q_NC,
        ),
        (
            "simple_pendulum",
            "theta",
            "-m g l sin(theta) + m g l theta",
            -m * g * l * sp.sin(theta) + m * g * l * theta,
            PENDULUM_V,
            theta,
            sp.S.Zero,
        ),
    ],
)
def test_a_q_with_the_conservative_part_and_more_names_the_part_and_the_rest(
    scene, coordinate, answer, by_hand, V, q, nonconservative
):
    read = reading(scene, "Q", answer, coordinate)
    assert sp.simplify(read - by_hand) == 0, read
    conservative = -sp.diff(V, q)
    rest = sp.expand(by_hand - nonconservative - conservative)
    assert conservative != 0 and rest != 0 and sp.expand(rest).is_Add is False  # one term
    v = check(derivation_of_scene(scene), "Q", answer, coordinate)
    assert v.correct is False, v.feedback
    assert "conservative part" in v.feedback[0] and "already in V" in v.feedback[0], v.feedback
    assert f"= {sp.latex(conservative)}$" in v.feedback[0], v.feedback
    assert any(f"Extra term ${sp.latex(rest)}$" in line for line in v.feedback), v.feedback
    # the conservative part is that part, not also an 'Extra term' beside it
    assert not any(sp.latex(conservative) in line for line in v.feedback[1:]), v.feedback
