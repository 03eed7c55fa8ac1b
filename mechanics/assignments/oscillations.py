"""Two parts beyond the checker's quantities: an equilibrium position and a small-oscillation
frequency, for a scene with one coordinate (a frequency of a scene with several: normal_modes.py).

- ``equilibrium``: q₀ where ∂V/∂q = 0, the root nearest the part's ``near`` value at the scene's
  parameters (the pendulum has two; the hanging spring one, m g / k).
- ``frequency``: ω = √(K/M) of small oscillations about the equilibrium ``at`` (default the
  part's ``near``, else q = 0): M the mass matrix there, K = ∂²V/∂q² there.

Keys come from the engine's derivation (its V and mass matrix); the second route linearises
sympy's LagrangesMethod (K = −∂f/∂q and M at the equilibrium, q̇ = 0) and finds q₀ from its
forcing. An answer is read by the engine's whitelist parser and compared at sampled parameter
values (then proved by sympy); the feedback names two usual slips: ω² for ω, and f = ω/2π.
"""

from __future__ import annotations

import math
import random
from typing import Any

import sympy as sp

from mechanics.derive import Derivation
from mechanics.expr import ExprError, parse, to_latex

from . import normal_modes
from .verify import Check, zero

QUANTITIES = ("equilibrium", "frequency")
SAMPLES = 8
TOLERANCE = 1e-9


def _plain_q(d: Derivation) -> tuple[sp.Symbol, dict]:
    """q as a plain symbol (and q̇ = 0: a static question)."""
    m = d.model
    q = sp.Symbol(m.coordinate_names[0], real=True)
    return q, {m.qdd[0]: 0, m.qd[0]: 0, m.q[0]: q}


def _values(d: Derivation) -> dict:
    return {sym: d.model.spec.parameters[name] for name, sym in d.model.params.items()}


def equilibrium_key(d: Derivation, near: float) -> sp.Expr:
    """The root of ∂V/∂q nearest ``near`` at the scene's parameter values."""
    q, static = _plain_q(d)
    force = sp.diff(d.work.V.subs(static), q)
    roots = [r for r in sp.solve(force, q) if r.is_real is not False]
    if not roots:
        raise ValueError("∂V/∂q has no root sympy can find: no equilibrium to ask for")
    values = _values(d)

    def distance(root: sp.Expr) -> float:
        value = complex(root.subs(values).evalf())
        return abs(value.imag) * 1e6 + abs(value.real - near)

    return sp.simplify(min(roots, key=distance))


def frequency_key(d: Derivation, at: sp.Expr) -> sp.Expr:
    """ω = √(K/M) at the equilibrium ``at`` (an expression of the parameters)."""
    q, static = _plain_q(d)
    mass = d.work.mass_matrix[0, 0].subs(static).subs(q, at)
    stiffness = sp.diff(d.work.V.subs(static), q, 2).subs(q, at)
    square = sp.simplify(stiffness / mass)
    if not complex(square.subs(_values(d)).evalf()).real > 0:
        raise ValueError(f"the equilibrium {q} = {at} is not stable: no oscillation to ask about")
    return sp.simplify(sp.sqrt(square))


def second_route(d: Derivation, quantity: str, near: float, at: sp.Expr | None) -> sp.Expr:
    """The same key from sympy's LagrangesMethod without the non-conservative loads (a static
    question), linearised by hand: q₀ where its forcing vanishes at rest, K = −∂f/∂q there."""
    from sympy.physics.mechanics import LagrangesMethod, Lagrangian

    from .second_route import potential

    m = d.model
    lagrangian = Lagrangian(m.N, *(b.sympy_body for b in m.bodies)) - potential(m)
    lm = LagrangesMethod(lagrangian, m.q, frame=m.N)
    lm.form_lagranges_equations()
    q, static = _plain_q(d)
    forcing = lm.forcing[0].subs(static)
    if quantity == "equilibrium":
        values = _values(d)
        roots = sp.solve(forcing, q)
        return min(roots, key=lambda r: abs(complex(r.subs(values).evalf()) - near))
    mass = lm.mass_matrix[0, 0].subs(static).subs(q, at)
    stiffness = -sp.diff(forcing, q).subs(q, at)
    return sp.sqrt(stiffness / mass)


def key(d: Derivation, part: dict[str, Any]) -> sp.Expr:
    near = float(part.get("near") or 0.0)
    if part["quantity"] == "frequency" and len(d.model.q) > 1:
        return normal_modes.key(d, part)
    if part["quantity"] == "equilibrium":
        return equilibrium_key(d, near)
    return frequency_key(d, equilibrium_key(d, near))


def verify(d: Derivation, part: dict[str, Any], engine: sp.Expr) -> Check:
    if part["quantity"] == "frequency" and len(d.model.q) > 1:
        return zero(engine - normal_modes.second_route(d, part), d.model)
    near = float(part.get("near") or 0.0)
    at = equilibrium_key(d, near) if part["quantity"] == "frequency" else None
    other = second_route(d, part["quantity"], near, at)
    return zero(engine - other, d.model)


def _at_samples(expr: sp.Expr, d: Derivation) -> list[complex]:
    rng = random.Random(5)
    out = []
    for _ in range(SAMPLES):
        values = {
            sym: sp.Float((d.model.spec.parameters[name] or 1.0) * rng.uniform(0.7, 1.3), 30)
            for name, sym in d.model.params.items()
        }
        try:
            out.append(complex(expr.xreplace(values).evalf(25)))
        except (TypeError, ValueError, ArithmeticError):
            out.append(complex("nan"))
    return out


def _same(a: list[complex], b: list[complex]) -> bool:
    return all(
        abs(x - y) <= TOLERANCE * max(1.0, abs(x), abs(y)) for x, y in zip(a, b, strict=True)
    )


def judge(d: Derivation, part: dict[str, Any], answer: str) -> dict[str, Any]:
    """The answer's verdict, in the checker's JSON shape; raises ExprError if it does not parse."""
    names = {k: v for k, v in d.model.names.items() if v in d.model.params.values()}
    given = parse(answer, names, field="answer", exact_decimals=True)
    if given.free_symbols - set(d.model.params.values()):
        raise ExprError("the answer may hold only the scene's parameters", field="answer")
    expected = key(d, part)
    mine, theirs = _at_samples(given, d), _at_samples(expected, d)
    feedback: list[str] = []
    correct = False
    if any(math.isnan(v.real) for v in mine):
        feedback.append("Your answer has no value at the scene's parameter values.")
    elif _same(mine, theirs):
        correct = sp.simplify(given - expected) == 0
        feedback.append(
            "Correct."
            if correct
            else "Not confirmed: equal at every sampled value, "
            "but sympy could not show it; write it more simply."
        )
    elif part["quantity"] == "frequency" and _same(mine, [v * v for v in theirs]):
        feedback.append("This is ω², not ω: take the square root.")
    elif part["quantity"] == "frequency" and _same(mine, [v / (2 * math.pi) for v in theirs]):
        feedback.append(
            "This is the frequency f = ω/2π in hertz: the angular frequency ω is asked."
        )
    elif _same(mine, [-v for v in theirs]):
        feedback.append("Sign error: your answer is the negative of the correct one.")
    else:
        feedback.append("Not equal to the correct value at the scene's parameter values.")
    return {
        "correct": correct,
        "confirmed": not feedback[0].startswith("Not confirmed"),
        "feedback": feedback,
        "answer_latex": to_latex(given),
    }
