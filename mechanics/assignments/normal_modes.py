"""A frequency part of a scene with several coordinates: the angular frequency of one normal mode
of small oscillations about an equilibrium (every coordinate at the part's ``near``, default 0).

ω_k² is the k-th smallest root λ of det(K − λ M) = 0 (``mode`` = k, from 1), with M the mass
matrix and K the Hessian of V at the equilibrium. The engine's key uses the derivation's V and
mass matrix; the second route linearises sympy's LagrangesMethod (without the non-conservative
loads) by hand: K = −∂f/∂q at rest. An equilibrium that is not one (∂V/∂q ≠ 0 there) or is
unstable (a λ ≤ 0) has no key: such a variant is never deployed.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from mechanics.derive import Derivation

#: Past this many coordinates det(K − λ M) is not solved symbolically.
MAX_COORDINATES = 3


def _static(d: Derivation) -> tuple[list[sp.Symbol], dict]:
    m = d.model
    qs = [sp.Symbol(name, real=True) for name in m.coordinate_names]
    swap: dict[Any, Any] = {}
    for qdd, qd in zip(m.qdd, m.qd, strict=True):
        swap[qdd] = 0
        swap[qd] = 0
    swap.update(dict(zip(m.q, qs, strict=True)))
    return qs, swap


def _values(d: Derivation) -> dict:
    return {sym: d.model.spec.parameters[name] for name, sym in d.model.params.items()}


def _mode(d: Derivation, M: sp.Matrix, K: sp.Matrix, mode: int) -> sp.Expr:
    """ω of the ``mode``-th mode (1: the slowest) from M and K at the equilibrium."""
    lam = sp.Symbol("lambda")
    roots = sp.solve((K - lam * M).det(), lam)
    values = _values(d)
    numbers = [complex(r.subs(values).evalf()) for r in roots]
    if len(roots) != len(d.model.q) or any(n.real <= 0 or abs(n.imag) > 1e-9 for n in numbers):
        raise ValueError("a mode has ω² ≤ 0 there (unstable, or a free coordinate): no frequency")
    ordered = [r for _, r in sorted(zip((n.real for n in numbers), roots, strict=True))]
    if not 1 <= mode <= len(ordered):
        raise ValueError(f"mode must be 1 to {len(ordered)}")
    return sp.sqrt(ordered[mode - 1])


def _at(d: Derivation, qs: list[sp.Symbol], near: float, V: sp.Expr) -> dict:
    at = {q: sp.nsimplify(near) for q in qs}
    values = _values(d)
    for q in qs:
        if abs(complex(sp.diff(V, q).subs(at).subs(values).evalf())) > 1e-9:
            raise ValueError(f"every coordinate at {near:g} is not an equilibrium")
    return at


def key(d: Derivation, part: dict[str, Any]) -> sp.Expr:
    if len(d.model.q) > MAX_COORDINATES:
        raise ValueError(f"normal modes are asked only of scenes with up to {MAX_COORDINATES}")
    qs, static = _static(d)
    V = d.work.V.subs(static)
    at = _at(d, qs, float(part.get("near") or 0.0), V)
    M = d.work.mass_matrix.subs(static).subs(at)
    K = sp.hessian(V, qs).subs(at)
    return _mode(d, M, K, int(part.get("mode") or 1))


def second_route(d: Derivation, part: dict[str, Any]) -> sp.Expr:
    from sympy.physics.mechanics import LagrangesMethod, Lagrangian

    from .second_route import potential

    m = d.model
    lagrangian = Lagrangian(m.N, *(b.sympy_body for b in m.bodies)) - potential(m)
    lm = LagrangesMethod(lagrangian, m.q, frame=m.N)
    lm.form_lagranges_equations()
    qs, static = _static(d)
    forcing = lm.forcing.subs(static)
    at = {q: sp.nsimplify(float(part.get("near") or 0.0)) for q in qs}
    K = -forcing.jacobian(qs).subs(at)
    M = lm.mass_matrix.subs(static).subs(at)
    return _mode(d, M, K, int(part.get("mode") or 1))
