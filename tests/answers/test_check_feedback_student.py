"""The answer checker's feedback as a student reads it (an instructor's play-test).

Each expectation is built here, independently of the engine: V from the scene file's own
positions, masses and gravity (V = Σ m g y, a spring's ½ k (stretch)²), −∂V/∂q by sympy on
plain symbols, equations of motion written by hand from the textbook ((m₁ + m₂) ẍ = (m₁ − m₂) g
for the Atwood machine, m l² θ̈ + m g l sin θ = 0 for the pendulum).
"""

from __future__ import annotations

import time
import tomllib
from importlib.resources import files

import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app
from mechanics.check import check
from mechanics.derive import derivation_of_scene, derive_model
from mechanics.units import fmt

client = TestClient(app)


def verdict(scene: str, quantity: str, answer: str, coordinate: str | None = None):
    return check(derivation_of_scene(scene), quantity, answer, coordinate)


def scene_file(scene: str) -> dict:
    return tomllib.loads(files("mechanics.scenes").joinpath(f"{scene}.toml").read_text())


def potential_from_file(scene: str) -> tuple[sp.Expr, dict[str, sp.Symbol]]:
    """V of a scene from its file alone: Σ m g (height) for uniform gravity along −y, plus
    ½ k (|r_b − r_a| − L0)² per spring between two points on the x axis (all the scenes here
    need). Positions are plain sympy of the file's text (the test's own reading of it)."""
    doc = scene_file(scene)
    names = [*doc["parameters"], *doc["coordinates"]]
    symbols = {n: sp.Symbol(n) for n in names}

    def read(text) -> sp.Expr:
        return sp.parse_expr(str(text), local_dict=symbols)

    positions = {"O": [sp.S.Zero] * 3}
    for point in doc.get("points", []):
        positions[point["name"]] = [read(c) for c in point["position"]]
    V = sp.S.Zero
    for body in doc["bodies"]:
        where = body["position"]
        if isinstance(where, dict):  # relative to another body, in N
            base = positions[where["from"]]
            where = [b + read(c) for b, c in zip(base, where["components"], strict=True)]
        else:
            where = [read(c) for c in where]
        positions[body["name"]] = where
        if "gravity" in doc:
            assert doc["gravity"]["direction"] == [0, -1, 0]
            V += read(body["mass"]) * read(doc["gravity"]["acceleration"]) * where[1]
    for spring in doc.get("springs", []):
        a, b = positions[spring["a"]], positions[spring["b"]]
        assert a[1] == b[1] == 0 and a[2] == b[2] == 0  # along x: the length is b_x − a_x here
        stretch = (b[0] - a[0]) - read(spring["rest_length"])
        V += read(spring["k"]) * stretch**2 / 2
    return V, symbols


# --- 1. Q_j (eq. 31, gravity included) where Q_j^NC is asked ---------------------------------


@pytest.mark.parametrize(
    "scene, coordinate, nonconservative",
    [
        ("rolling_disk", "x", "0"),
        ("atwood_machine", "x", "0"),
        ("cart_pendulum", "theta", "0"),
        ("spring_mass_damper", "x", "F0*cos(w*t) - c*x_dot"),  # drive and damper, by hand
    ],
)
def test_a_q_with_the_conservative_part_says_so(scene, coordinate, nonconservative):
    V, symbols = potential_from_file(scene)
    conservative = -sp.diff(V, symbols[coordinate])
    assert conservative != 0
    answer = f"({nonconservative}) + ({sp.sstr(conservative)})"  # eq. 31: every force
    v = verdict(scene, "Q", answer, coordinate)
    assert v.correct is False, v.feedback
    text = " ".join(v.feedback)
    assert "conservative part" in text and "already in V" in text, v.feedback
    assert "^{NC}" in text and "Extra term" not in text, v.feedback
    # the same answer without −∂V/∂q is the one asked for
    assert verdict(scene, "Q", nonconservative, coordinate).correct is True


def test_a_q_wrong_otherwise_is_not_said_to_hold_the_conservative_part():
    V, symbols = potential_from_file("rolling_disk")
    conservative = -sp.diff(V, symbols["x"])
    # (−(−∂V/∂x), the part with its sign flipped, is named as such: test_check_feedback_your_turn)
    for answer in (f"2*({sp.sstr(conservative)})", "m*g"):
        v = verdict("rolling_disk", "Q", answer, "x")
        assert v.correct is False
        assert "conservative part" not in " ".join(v.feedback), (answer, v.feedback)


# --- 2. a constant added to V must be an energy -----------------------------------------------


RIGHT = {  # by hand: the bob at l (sin θ, −cos θ), speed l θ̇, height −l cos θ
    "T": "m*l**2*theta_dot**2/2",
    "V": "-m*g*l*cos(theta)",
    "L": "m*l**2*theta_dot**2/2 + m*g*l*cos(theta)",
}


@pytest.mark.parametrize("quantity", ["T", "V", "L"])
@pytest.mark.parametrize("added", ["m", "l", "g", "5"])
def test_a_constant_that_is_no_energy_is_a_unit_error_in_t_v_and_l(quantity, added):
    right = RIGHT[quantity]
    v = verdict("simple_pendulum", quantity, f"{right} + {added}")
    assert v.correct is False, v.feedback
    said = ("units", "a pure number")  # a bare 5: a pure number (test_check_feedback_your_turn)
    assert any(any(w in line for w in said) and "not an energy" in line for line in v.feedback), (
        v.feedback
    )


@pytest.mark.parametrize("quantity", ["V", "L"])
@pytest.mark.parametrize("added", ["m*g*l", "5*m*g*l", "m*l**2*g/(2*l)"])
def test_a_constant_that_is_an_energy_only_moves_the_datum(quantity, added):
    v = verdict("simple_pendulum", quantity, f"{RIGHT[quantity]} + {added}")
    assert v.correct is True, v.feedback


def test_without_units_a_number_is_a_datum():
    doc = scene_file("simple_pendulum")
    doc.pop("units")
    d = derive_model(doc)
    v = check(d, "V", "-m*g*l*cos(theta) + 5")
    assert v.correct is True, v.feedback


# --- 3. feedback that names the real error ---------------------------------------------------


def test_a_wrong_inertia_term_is_named_not_the_forces():
    # by hand: (m1 + m2) ẍ = (m1 − m2) g; the student wrote (m1 − m2) for the inertia
    v = verdict("atwood_machine", "eom", "(m1-m2) x'' = (m1-m2) g", "x")
    assert v.correct is False
    text = " ".join(v.feedback)
    assert "inertia term" in text and "m_{1} + m_{2}" in text, v.feedback
    assert "multiplied by" not in text, v.feedback  # (m1 − m2)/(m1 + m2) is 0 at m1 = m2


def test_an_equation_is_never_read_as_scaled_by_a_factor_that_can_vanish():
    # (m1 − m2) times the right equation, plus a wrong term: no reading 'multiplied by (m1 − m2)'
    v = verdict("atwood_machine", "eom", "(m1-m2)*((m1+m2) x'' - (m1-m2) g) + x", "x")
    assert v.correct is False
    assert not any("multiplied by" in line for line in v.feedback), v.feedback
    # a factor no parameter value but 0 makes vanish is still a scaling to read by
    v = verdict("simple_pendulum", "eom", "theta'' + g/l sin(theta) + theta", "theta")
    assert any("multiplied by" in line for line in v.feedback), v.feedback


def test_one_explanation_for_a_sign_that_is_also_a_swap():
    v = verdict("atwood_machine", "eom", "(m1+m2) x'' = (m2-m1) g", "x")
    assert v.correct is False
    assert len(v.feedback) == 1, v.feedback
    assert v.feedback[0].startswith("Sign error"), v.feedback


@pytest.mark.parametrize("answer", ["theta'' = theta''", "m l^2 theta'' = m l^2 theta''", "0 = 0"])
def test_an_identity_is_called_one(answer):
    v = verdict("simple_pendulum", "eom", answer, "theta")
    assert v.correct is False
    text = " ".join(v.feedback)
    assert "0 = 0" in text and "identity" in text, v.feedback
    assert "yours has none" not in text and "Missing term" not in text, v.feedback


def test_accelerations_that_cancel_are_said_to_cancel():
    v = verdict("simple_pendulum", "eom", "theta'' + g/l sin(theta) = theta''", "theta")
    assert v.correct is False
    assert "cancel" in v.feedback[0] and "yours has none" not in v.feedback[0], v.feedback


def test_units_with_two_factors_below_the_line_are_bracketed():
    assert fmt((0, -1, -2)) == "1/(m·s²)"
    assert fmt((1, -1, -2)) == "kg/(m·s²)"
    assert fmt((1, 2, -2)) == "kg·m²/s²" and fmt((0, 0, -1)) == "1/s"
    # g/l² is (m/s²)/m² = 1/(m s²), in a V that must be an energy
    v = verdict("simple_pendulum", "V", "-m*g*l*cos(theta) + g/l^2*theta")
    text = " ".join(v.feedback)
    assert "1/(m·s²)" in text and "1/m·s²" not in text, v.feedback


def test_a_spring_written_with_x_minus_rest_length_is_explained():
    doc = scene_file("spring_mass_damper")
    (block,) = doc["bodies"]
    (spring,) = doc["springs"]
    x, L0 = sp.symbols("x L0")
    # the file puts the block at L0 + x from the wall: x is the stretch itself
    assert sp.parse_expr(block["position"][0]) - sp.Symbol(spring["rest_length"]) == x
    V, _ = potential_from_file("spring_mass_damper")
    assert sp.expand(V - sp.Symbol("k") * x**2 / 2) == 0
    v = verdict("spring_mass_damper", "V", "1/2 k (x - L0)^2")
    assert v.correct is False
    text = " ".join(v.feedback)
    assert "rest length" in text and "L_{0} + x" in text, v.feedback
    assert "Extra term" not in text, v.feedback


# --- 4. common notations ---------------------------------------------------------------------


@pytest.mark.parametrize(
    "answer, correct",
    [
        ("-m g l cos(theta) (sin^2 theta + cos^2(theta))", True),  # only if sin^2 θ is sin(θ)²
        ("-m g l cos(theta) (sin^2(theta) + cos^2 θ)", True),
        ("-m g l cos(theta) (sin²θ + cos²θ)", True),
        ("-m g l cos(theta) + m g l sin^2(theta)", False),
    ],
)
def test_sin_squared_notation_reads_as_the_square(answer, correct):
    v = verdict("simple_pendulum", "V", answer)
    assert v.correct is correct, v.feedback


@pytest.mark.parametrize(
    "scene, coordinate, answer, correct",
    [
        # by hand: d/dt(m l² θ̇) + m g l sin θ = 0
        ("simple_pendulum", "theta", "d/dt(m l^2 theta') + m g l sin(theta) = 0", True),
        ("simple_pendulum", "theta", "d/dt (m l^2 θ') = -m g l sin θ", True),
        ("simple_pendulum", "theta", "d/dt(m l^2 theta) + m g l sin(theta) = 0", False),
        # d is a parameter of the Atwood machine: d/dt is still the operator
        ("atwood_machine", "x", "d/dt((m1 + m2) x') = (m1 - m2) g", True),
        ("atwood_machine", "x", "d/dt((m1 + m2) x') = (m1 + m2) g", False),
    ],
)
def test_d_dt_is_the_total_time_derivative(scene, coordinate, answer, correct):
    v = verdict(scene, "eom", answer, coordinate)
    assert v.correct is correct, v.feedback


@pytest.mark.parametrize(
    "answer, says",
    [
        ("sin^-1(theta)", "asin"),
        ("sin^x(theta)", "sin^2(theta)"),
        ("sin^2^2(theta)", "sin^2(theta)"),  # was read as sin(θ)², the second power dropped
        ("d/dt(abs(theta))", "abs()"),  # sympy's d|θ(t)|/dt is in re() and im()
        ("m g l sin^2", "sin^2(theta)"),
        ("d/dt m l^2 theta'", "parentheses"),
        ("d/dt(theta'')", "third derivative"),
        ("d/dt(d/dt(theta))", "second derivative"),
        ("d/dt(theta", "never closed"),
        ("d/dt(" + "*".join(f"(theta + {k})" for k in range(1, 60)) + ")", "too long"),
    ],
)
def test_what_is_not_read_is_a_clean_422_on_answer(answer, says):
    start = time.perf_counter()
    r = client.post(
        "/api/v1/check",
        json={"scene_id": "simple_pendulum", "quantity": "V", "answer": answer},
    )
    assert time.perf_counter() - start < 10
    assert r.status_code == 422, r.text
    (problem,) = r.json()["detail"]
    assert set(problem) == {"field", "message"} and problem["field"] == "answer", problem
    assert says in problem["message"], problem
