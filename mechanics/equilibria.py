"""Equilibrium by virtual work (notes II.A), stability, and small oscillations about it.

At rest every q̇ and q̈ vanish, and the equations of motion reduce to f_j(q, 0, t) = 0: for a
scleronomic system that is δW = Σ_j (Q_j^NC − ∂V/∂q_j) δq_j = 0 for arbitrary δq_j; where frames
turn at a prescribed rate it also keeps the centrifugal terms, which is what "equilibrium in the
rotating frame" means (the bead on a spinning hoop). Solutions are found symbolically where sympy
can (with the conditions under which they exist), numerically otherwise. Linearizing about each
gives M δq̈ + C δq̇ + K δq = 0; K v = ω² M v gives the normal modes.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.linalg
import scipy.optimize
import sympy as sp

from mechanics.derive import Derivation
from mechanics.expr import to_latex, to_plain
from mechanics.model import T as t
from mechanics.spec import SpecError
from mechanics.steps import Line, Step, tidy
from mechanics.steps.conserved import explicit_time

SYMBOLIC_OPS_LIMIT = 200
TOL = 1e-9


def equilibria(d: Derivation, parameters: dict[str, float] | None = None) -> dict[str, Any]:
    """Steps in the notes' order and every equilibrium at the given parameter values."""
    m, w = d.model, d.work
    values = {m.params[k]: sp.Float(v) for k, v in _checked(d, parameters or {}).items()}
    rest = {**dict.fromkeys(m.qdd, 0), **dict.fromkeys(m.qd, 0)}
    conditions = [tidy(fj.xreplace(rest), m) for fj in w.forcing]
    steps = [_virtual_work_step(d, conditions)]
    warnings: list[str] = []
    conditions = [_drop_idle_drive(c, m, values) for c in conditions]
    if any(explicit_time(c, m) for c in conditions):
        warnings.append(
            "The forces at rest depend on time (a drive): there is no fixed "
            "equilibrium. Set the drive amplitude to 0 to find the undriven ones."
        )
        return {"steps": [s.to_json() for s in steps], "equilibria": [], "warnings": warnings}
    free = [j for j, c in enumerate(conditions) if c == 0]
    bound = [j for j in range(len(m.q)) if j not in free]
    found = _symbolic(d, conditions, bound, values) if bound else [({}, {}, "always")]
    if found is None:
        found = _numeric(d, conditions, bound, values)
        warnings.append(
            "sympy could not solve the conditions in closed form: the equilibria "
            "below were found numerically."
        )
    results, linearized = [], []
    for numeric_q, symbolic_q, exists in found:
        q0 = [numeric_q.get(j, 0.0) for j in range(len(m.q))]
        stable, freqs, modes, linear = _stability(d, q0, len(free), values)
        linearized.append(linear)
        results.append(
            {
                "q": {m.coordinate_names[j]: q0[j] for j in range(len(m.q))},
                "symbolic": {m.coordinate_names[j]: to_plain(symbolic_q[j]) for j in symbolic_q},
                "free": [m.coordinate_names[j] for j in free],
                "exists_when": exists,
                "stable": stable,
                "frequencies": freqs,
                "modes": modes,
            }
        )
    order = sorted(range(len(results)), key=lambda i: [abs(v) for v in results[i]["q"].values()])
    results, linearized = [results[i] for i in order], [linearized[i] for i in order]
    steps.append(_stability_step(d, results, linearized))
    if not results:
        warnings.append("No equilibrium: the forces at rest never balance at these parameters.")
    return {"steps": [s.to_json() for s in steps], "equilibria": results, "warnings": warnings}


def _drop_idle_drive(c: sp.Expr, m: Any, values: dict) -> sp.Expr:
    """Terms with explicit t that vanish at these parameters (a drive set to 0) are dropped."""
    terms = sp.Add.make_args(sp.expand(c))
    idle = [a for a in terms if explicit_time(a, m) and a.xreplace(values) == 0]
    return tidy(c - sp.Add(*idle), m) if idle else c


def _checked(d: Derivation, parameters: dict[str, float]) -> dict[str, float]:
    m = d.model
    errors = []
    for name, value in parameters.items():
        if name not in m.params:
            errors.append({"field": f"parameters.{name}", "message": f"unknown parameter '{name}'"})
        elif not math.isfinite(value):
            errors.append({"field": f"parameters.{name}", "message": "must be a finite number"})
        elif m.params[name].is_nonnegative and value < 0:
            errors.append({"field": f"parameters.{name}", "message": "must be ≥ 0"})
    if errors:
        raise SpecError(errors)
    return {**m.spec.parameters, **parameters}


def _virtual_work_step(d: Derivation, conditions: list[sp.Expr]) -> Step:
    m = d.model
    lines = []
    for b in m.bodies:
        delta = sum(
            (b.position.diff(q, m.N) * sp.Symbol(rf"\delta {to_latex(q)}") for q in m.q),
            sp.S.Zero * m.N.x,
        )
        if delta != 0:
            lines.append(
                Line(
                    f"delta r {b.name}",
                    rf"\delta\vec{{r}}_{{\text{{{b.name}}}}} = "
                    f"{to_latex(delta.simplify())}",
                    f"delta r_{b.name}",
                )
            )
    for name, q, c in zip(m.coordinate_names, m.q, conditions, strict=True):
        lines.append(
            Line(
                f"Q_{name} at rest",
                rf"Q_{{{to_latex(q)}}}\big|_{{\dot q = 0}} = "
                f"{to_latex(c)} = 0",
                f"Q_{name} = {to_plain(c)} = 0",
            )
        )
    text = (
        "Constraint forces do no virtual work, so only the applied forces enter: "
        "δW = Σ_j Q_j δq_j with Q_j = Q_j^NC − ∂V/∂q_j evaluated at rest (q̇ = 0; where a "
        "frame turns at a prescribed rate, the equations of motion at q̇ = q̈ = 0). The δq_j "
        "are arbitrary, so each Q_j must vanish (notes II.A, eq. 18)."
    )
    return Step("virtual_work", "Equilibrium by virtual work", text, lines)


def _symbolic(d, conditions, bound, values):
    """Closed-form roots with their existence conditions, or None when sympy cannot."""
    m = d.model
    eqs = [conditions[j] for j in bound]
    if len(bound) > 2 or sum(sp.count_ops(e) for e in eqs) > SYMBOLIC_OPS_LIMIT:
        return None
    subs = {m.q[j]: sp.Symbol(f"_q{j}", real=True) for j in bound}
    back = {v: k for k, v in subs.items()}
    try:
        sols = sp.solve([e.xreplace(subs) for e in eqs], list(subs.values()), dict=True)
    except (NotImplementedError, ValueError, TypeError):
        return None
    if not sols and not all(_never_zero(e, values) for e in eqs):
        return None
    out = []
    seen: list[list[float]] = []
    for sol in sols:
        if len(sol) < len(bound):
            return None
        numeric, symbolic, conditions_text = {}, {}, []
        ok = True
        for j in bound:
            expr = sol[subs[m.q[j]]].xreplace(back)
            conditions_text += _existence(expr)
            value = complex(expr.xreplace(values).evalf())
            if abs(value.imag) > 1e-12 or not math.isfinite(value.real):
                ok = False
                break
            wrapped, turns = _wrap(value.real, m.spec.units.get(m.coordinate_names[j]))
            numeric[j] = wrapped
            symbolic[j] = expr - 2 * sp.pi * turns if turns else expr
        if not ok:
            continue
        key = [numeric[j] for j in bound]
        if any(np.allclose(key, s, atol=1e-9) for s in seen):
            continue
        seen.append(key)
        out.append((numeric, symbolic, " and ".join(conditions_text) or "always"))
    return out


def _never_zero(expr, values) -> bool:
    return not expr.free_symbols - set(values) - {t}


def _existence(expr: sp.Expr) -> list[str]:
    """acos(u), asin(u) need |u| ≤ 1; sqrt(u) needs u ≥ 0 — the notes' 'only when Ω² > g/R'."""
    out = []
    for f in expr.atoms(sp.acos, sp.asin):
        out.append(f"|{to_plain(f.args[0])}| <= 1")
    for p in expr.atoms(sp.Pow):
        if p.exp == sp.Rational(1, 2) and not p.base.is_nonnegative:
            out.append(f"{to_plain(p.base)} >= 0")
    return out


def _wrap(value: float, unit: str | None) -> tuple[float, int]:
    """Angles into (−π, π]; returns the value and the whole turns taken off."""
    if unit != "rad":
        return value, 0
    turns = math.floor((value + math.pi) / (2 * math.pi))
    wrapped = value - 2 * math.pi * turns
    if wrapped <= -math.pi + 1e-12:
        wrapped += 2 * math.pi
        turns -= 1
    return wrapped, turns


def _numeric(d, conditions, bound, values):
    """Roots from a grid of starting points, deduplicated; angles wrapped."""
    m = d.model
    f = sp.lambdify(
        [[m.q[j] for j in bound]], [conditions[j].xreplace(values) for j in bound], modules="numpy"
    )
    starts = []
    rng = np.random.default_rng(0)
    for _ in range(40):
        starts.append(
            [
                rng.uniform(-math.pi, math.pi)
                if m.spec.units.get(m.coordinate_names[j]) == "rad"
                else rng.uniform(-2, 2)
                for j in bound
            ]
        )
    found: list[list[float]] = []
    for x0 in starts:
        sol = scipy.optimize.root(lambda x: np.asarray(f(list(x)), dtype=float), x0)
        if not sol.success or np.max(np.abs(f(list(sol.x)))) > 1e-8:
            continue
        x = [
            _wrap(v, m.spec.units.get(m.coordinate_names[j]))[0]
            for v, j in zip(sol.x, bound, strict=True)
        ]
        if not any(np.allclose(x, y, atol=1e-7) for y in found):
            found.append(x)
    return [({j: v for j, v in zip(bound, x, strict=True)}, {}, "numeric") for x in found]


def _stability(d, q0, n_free, values):
    """K = −∂f/∂q, C = −∂f/∂q̇ at rest; stable when no mode grows.

    Every coordinate takes part (a free cart still moves with its pendulum), except one whose
    mass-matrix row vanishes there: a coordinate singularity such as φ at the pole of a sphere.
    Zero-frequency modes are neutral where coordinates are free (cyclic), unstable otherwise.
    """
    m, w = d.model, d.work
    point = {**values, **{q: sp.Float(v) for q, v in zip(m.q, q0, strict=True)}}
    rest = {**dict.fromkeys(m.qdd, 0), **dict.fromkeys(m.qd, 0)}

    def num(e):
        return float(sp.S.Zero + e.xreplace(rest).xreplace(point))

    n = len(m.q)
    full_M = np.array([[num(w.mass_matrix[j, k]) for k in range(n)] for j in range(n)])
    idx = [j for j in range(n) if abs(full_M[j, j]) > 1e-12]
    n_free -= n - len(idx)
    f = [w.forcing[j] for j in idx]
    K = np.array([[-num(fj.diff(m.q[k])) for k in idx] for fj in f])
    C = np.array([[-num(fj.diff(m.qd[k])) for k in idx] for fj in f])
    M = full_M[np.ix_(idx, idx)]
    if not idx:
        return True, [], [], None
    A = np.block(
        [[np.zeros_like(M), np.eye(len(idx))], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]]
    )
    growth = np.max(np.linalg.eigvals(A).real)
    w2, vecs = scipy.linalg.eigh((K + K.T) / 2, M)
    zero = np.abs(w2) <= TOL * max(1.0, np.max(np.abs(w2)))
    stable = bool(growth <= 1e-7 and np.all(w2 > -TOL) and zero.sum() <= max(n_free, 0))
    freqs, modes = [], []
    if stable:
        for i in np.argsort(w2):
            if zero[i]:
                continue
            v = vecs[:, i] / np.max(np.abs(vecs[:, i]))
            mode = [0.0] * n
            for j, x in zip(idx, v, strict=True):
                mode[j] = float(x)
            freqs.append(float(math.sqrt(w2[i])))
            modes.append(mode)
    linear = {"M": M, "C": C, "K": K, "coordinates": [m.q[j] for j in idx]}
    return stable, freqs, modes, linear


def _matrix(a: np.ndarray) -> str:
    return to_latex(sp.Matrix(a.shape[0], a.shape[1], [sp.Float(float(x), 5) for x in a.flat]))


def _linear_latex(linear: dict) -> str:
    """M δq̈ + C δq̇ + K δq = 0 with the numbers at this equilibrium and these parameters."""
    qs = linear["coordinates"]
    dq = to_latex(sp.Matrix([sp.Symbol(rf"\delta {to_latex(q)}") for q in qs]))
    dqd = to_latex(sp.Matrix([sp.Symbol(rf"\delta \dot{{{to_latex(q)}}}") for q in qs]))
    dqdd = to_latex(sp.Matrix([sp.Symbol(rf"\delta \ddot{{{to_latex(q)}}}") for q in qs]))
    damping = "" if not np.any(linear["C"]) else f" + {_matrix(linear['C'])}{dqd}"
    return f"{_matrix(linear['M'])}{dqdd}{damping} + {_matrix(linear['K'])}{dq} = 0"


def _stability_step(d: Derivation, results: list[dict], linearized: list) -> Step:
    text = (
        "About each equilibrium q₀ the motion linearizes to M δq̈ + C δq̇ + K δq = 0 with "
        "K = −∂f/∂q and C = −∂f/∂q̇ at rest. It is stable when no mode grows; then "
        "K v = ω² M v gives the small-oscillation frequencies and normal modes."
    )
    lines = []
    for r, linear in zip(results, linearized, strict=True):
        q = ", ".join(f"{k} = {v:.4g}" for k, v in r["q"].items())
        if linear is not None:
            lines.append(
                Line(
                    f"linearized about {q}",
                    _linear_latex(linear),
                    f"M = {linear['M'].tolist()}, C = {linear['C'].tolist()}, "
                    f"K = {linear['K'].tolist()}",
                )
            )
        verdict = "stable" if r["stable"] else "unstable"
        freqs = ", ".join(f"{f:.4g}" for f in r["frequencies"])
        lines.append(
            Line(
                q,
                rf"\text{{{q}: {verdict}}}"
                + (
                    rf"\quad \omega = {freqs}\ "
                    r"\mathrm{rad/s}"
                    if freqs
                    else ""
                ),
                f"{q}: {verdict} {freqs}",
            )
        )
    return Step("stability", "Stability and small oscillations", text, lines)
