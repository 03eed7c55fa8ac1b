"""The equilibria's text speaks the derivation's notation, and its notes say what happened.

A student play-tester found three things (round 3):
1. the stability step wrote the mass matrix as italic M, while the matrix-form step writes it
   bold (and in the cart pendulum M is the cart's mass); the virtual-work step was plain
   Unicode ('Q_j = Q_j^NC − ∂V/∂q_j') among typeset steps;
2. 'their power Σ_j Q_j q̇_j' meant the non-conservative forces' power, while the forces step
   defines Q_j = Q_j^NC − ∂V/∂q_j: Q_j had two meanings;
3. the double pendulum's note said 'sympy could not solve the conditions in closed form' while
   every entry showed a closed form (θ = 0, π), and sympy had not been asked at all.

The expectations come from elsewhere: the matrix-form and forces steps (other modules) for the
notation, and closed forms by hand for the values (sin θ1 = sin θ2 = 0; tan θ = F/(m g)).
"""

from __future__ import annotations

import math
import re

import pytest
from test_equilibria_math import NAMES, named_e_and_q, result_of, words_and_math
from test_equilibria_nc import cubic, trap

from mechanics.derive import derivation_of_scene, derive_model
from mechanics.equilibria import equilibria
from mechanics.scenes import load_scene

#: Notation that must stand inside $…$ in a step's prose.
NOTATION = ("δ", "∂", "Σ", "−", "q̇", "q̈", "_", "^", "\\")


def steps_of(result: dict) -> dict[str, dict]:
    return {s["id"]: s for s in result["steps"]}


def bare_matrix(tex: str) -> bool:
    """A math part that names K, C or M as a matrix without \\mathbf: '$K$', 'K =', 'M\\,'
    (a parameter M in an expression, 'M \\dot{x}', is not a matrix)."""
    for found in re.finditer(r"(?<![\\A-Za-z])[KCM](?![A-Za-z])", tex):
        if tex[: found.start()].rstrip(" {").endswith(r"\mathbf"):
            continue
        after = tex[found.end() :].lstrip()
        if not after or after.startswith(("=", r"\,", r"\delta")):
            return True
    return False


def test_bare_matrix_sees_the_old_text():
    """The check can fail: the old step's equation and reasons are caught, the new are not."""
    assert bare_matrix(r"M\,\delta\ddot q + C\,\delta\dot q + K\,\delta q = 0")
    assert bare_matrix("K") and bare_matrix(r"K = -\partial f/\partial q")
    assert not bare_matrix(r"\mathbf M\,\delta\ddot q + \mathbf C\,\delta\dot q")
    assert not bare_matrix(r"\mathbf K") and not bare_matrix(r"\lambda = \pm 2i")


def test_the_stability_step_writes_the_matrices_as_the_matrix_step_does():
    """The matrix-form step writes bold M (a parameter M, the cart's mass, is italic); the
    stability step's equation, and every reason of the catalog and the posted specs, write
    M, C and K bold too."""
    d = derivation_of_scene("simple_pendulum")
    matrix = next(s for s in d.steps if s.id == "matrix").to_json()
    assert r"\mathbf M" in matrix["text"]
    stability = steps_of(equilibria(d, {}))["stability"]
    _, maths = words_and_math(stability["text"])
    assert r"\mathbf M\,\delta\ddot q + \mathbf C\,\delta\dot q + \mathbf K\,\delta q = 0" in maths
    assert not any(bare_matrix(tex) for tex in maths), maths
    for name in NAMES:
        result = result_of(name)
        for e in result["equilibria"]:
            _, maths = words_and_math(e["reason"])
            assert not any(bare_matrix(tex) for tex in maths), (name, e["reason"])
        for step in result["steps"]:
            _, maths = words_and_math(step["text"])
            assert not any(bare_matrix(tex) for tex in maths), (name, step["text"])


def test_a_cart_s_mass_m_is_not_the_mass_matrix():
    """The cart pendulum has a parameter M, the cart's mass; undriven (F = 0) its rests are
    judged, and no text writes a bare $M$. The bottom swings at ω² = g (M + m)/(M l) (by hand:
    the cart recoils), so the M in it is the cart's."""
    p = load_scene("cart_pendulum")["parameters"]
    assert "M" in p
    result = equilibria(derivation_of_scene("cart_pendulum"), {"F": 0.0})
    assert "stability" in steps_of(result)
    texts = [s["text"] for s in result["steps"]] + [e["reason"] for e in result["equilibria"]]
    texts += result["warnings"]
    assert not any("$M$" in t or bare_matrix(m) for t in texts for m in words_and_math(t)[1])
    # the free cart drifts: the bottom is neutral, not stable (issue 25, item 3)
    bottom = next(e for e in result["equilibria"] if e["kind"] == "marginal")
    omega = math.sqrt(p["g"] * (p["M"] + p["m"]) / (p["M"] * p["l"]))
    assert bottom["frequencies"] == [pytest.approx(omega, rel=1e-6)]


@pytest.mark.parametrize("sid", ["simple_pendulum", "spring_mass_damper", "cart_pendulum"])
def test_the_virtual_work_step_is_typeset_in_the_forces_step_letters(sid):
    """Its notation sits in $…$, and Q_j there is the forces step's Q_j = Q_j^NC − ∂V/∂q_j
    (quoted from that step, an other module), so Q_j has one meaning in the derivation."""
    d = derivation_of_scene(sid)
    step = steps_of(equilibria(d, {}))["virtual_work"]
    words, maths = words_and_math(step["text"])
    for text in words:
        for mark in NOTATION:
            assert mark not in text, f"{mark!r} outside $…$ in {step['text']!r}"
    relation = r"Q_j = Q_j^{NC} - \partial V/\partial q_j"
    forces = next(s for s in d.steps if s.id == "forces").to_json()
    if d.model.loads:  # the forces step states the relation only where a force is not in V
        assert relation in words_and_math(forces["text"])[1]
    assert relation in maths
    assert r"\delta W = \sum_j Q_j\,\delta q_j" in maths


def test_a_parameter_named_q_leaves_its_letter_in_the_virtual_work_step():
    """With a parameter Q the forces step writes the generalized forces 𝒬_j; so does this step,
    in its prose and in its condition lines (Q alone is the parameter)."""
    spec = named_e_and_q(True)
    d = derive_model(spec)
    forces = next(s for s in d.steps if s.id == "forces").to_json()
    assert r"\mathcal{Q}_j" in forces["text"]
    step = steps_of(equilibria(d, {}))["virtual_work"]
    _, maths = words_and_math(step["text"])
    assert r"\mathcal{Q}_j = \mathcal{Q}_j^{NC} - \partial V/\partial q_j" in maths
    assert not any(re.search(r"(?<![\\{A-Za-z])Q(?![A-Za-z])", tex) for tex in maths), maths
    conditions = [line for line in step["latex"] if r"\big|_{\dot q = 0}" in line]
    assert conditions and all(line.startswith(r"\mathcal{Q}_{x}") for line in conditions)


def test_the_power_is_the_non_conservative_forces_power():
    """F = c ẋ³: Q_x^NC = c ẋ³, no part at rest, so the power is Σ_j Q_j^NC q̇_j = c ẋ⁴ (by hand)."""
    (e,) = equilibria(derive_model(cubic(0.1)), {})["equilibria"]
    assert r"$\sum_j Q_j^{NC} \dot q_j = c \dot{x}^{4}$" in e["reason"]
    assert r"\sum_j Q_j \dot q_j" not in e["reason"]


def test_a_force_that_also_acts_at_rest_keeps_that_part_out_of_the_power():
    """F = (P + c ẋ³) x̂ with a spring k: at rest P balances k x, x = P/k (by hand); the power
    shown, c ẋ⁴, is Σ_j (Q_j^NC − Q_j^NC|_{q̇=0}) q̇_j, not Σ_j Q_j^NC q̇_j = P ẋ + c ẋ⁴, and the
    symbol says so."""
    spec = cubic(0.1)
    spec["parameters"]["P"] = 1.0
    spec["forces"][0]["vector"] = ["P + c*x_dot**3", 0, 0]
    (e,) = equilibria(derive_model(spec), {})["equilibria"]
    assert e["q"]["x"] == pytest.approx(1.0 / 4.0)
    power = r"\sum_j (Q_j^{NC} - Q_j^{NC}|_{\dot q = 0})\,\dot q_j = c \dot{x}^{4}"
    assert f"${power}$" in e["reason"], e["reason"]


def test_forces_that_do_no_work_say_so_in_the_same_letters():
    """The magnetic force q B (ẏ, −ẋ): Σ_j Q_j^NC q̇_j = q B (ẏ ẋ − ẋ ẏ) = 0 (by hand)."""
    spec = trap(["q*B*y_dot", "-q*B*x_dot", 0], k=1.0, B=0.5)
    (e,) = equilibria(derive_model(spec), {})["equilibria"]
    assert r"their power $\sum_j Q_j^{NC} \dot q_j = 0$" in e["reason"], e["reason"]


def test_the_double_pendulum_note_says_what_happened():
    """sin θ1 = 0 and sin θ2 = 0 (by hand: Q_θ1 = −(m1 + m2) g l1 sin θ1, Q_θ2 = −m2 g l2 sin θ2):
    four rests at 0 and π, each listed with its closed form. The note must not say sympy failed
    to solve what it was never asked, nor that the roots are numbers only."""
    result = equilibria(derivation_of_scene("double_pendulum"), {})
    found = {(round(e["q"]["theta1"], 9), round(e["q"]["theta2"], 9)) for e in result["equilibria"]}
    pi = round(math.pi, 9)
    assert found == {(0.0, 0.0), (0.0, pi), (pi, 0.0), (pi, pi)}
    assert all(set(e["symbolic"]) == {"theta1", "theta2"} for e in result["equilibria"])
    assert not any("could not" in w for w in result["warnings"]), result["warnings"]
    (note,) = [w for w in result["warnings"] if "numeric search" in w]
    assert "not asked" in note and "each was recognised in closed form" in note
    assert "numbers only" not in note


def test_roots_without_a_closed_form_are_said_to_be_numbers_only():
    """A push F on the lower bob: tan θ2 = F/(m2 g), tan θ1 = F/((m1 + m2) g) (by hand), not a
    simple multiple of π: the entries carry no closed form, and the note says so."""
    spec = load_scene("double_pendulum")
    spec["parameters"]["F"] = 3.0
    spec["forces"] = [{"name": "push", "on": "bob2", "vector": ["F", 0, 0]}]
    result = equilibria(derive_model(spec), {})
    g = spec["parameters"]["g"]
    stable = [e for e in result["equilibria"] if e["kind"] == "stable"]
    assert len(stable) == 1
    assert stable[0]["q"]["theta1"] == pytest.approx(math.atan(3.0 / (2 * g)))
    assert stable[0]["q"]["theta2"] == pytest.approx(math.atan(3.0 / g))
    assert all(not e["symbolic"] for e in result["equilibria"])
    (note,) = [w for w in result["warnings"] if "numeric search" in w]
    assert "numbers only" in note and "each was recognised" not in note
