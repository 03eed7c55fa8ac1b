"""Independent expectations for the beyond-the-catalog acceptance set.

Nothing here imports the engine's model or oracle: each reference system is written by hand
(positions, a Lagrangian, forces) and handed to sympy's own `LagrangesMethod`, or given in
closed form. The engine's M and f are read back only by the *names* of their symbols, so the
comparison does not depend on the engine's symbol objects (a positive coordinate is a different
sympy function from a plain one, but both print as `r`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from sympy.core.function import AppliedUndef
from sympy.physics.mechanics import LagrangesMethod, Point
from sympy.physics.vector import ReferenceFrame, Vector, dynamicsymbols

t = dynamicsymbols._t


@dataclass
class Reference:
    """M(q, t) q̈ = f(q, q̇, t) of an independently written system, numerically callable."""

    names: list[str]
    params: list[str]
    mass_and_forcing: Callable  # (t, *q, *u, *params) -> (M, f) as nested lists

    def numeric(self, time: float, q: Sequence[float], u: Sequence[float], p: dict[str, float]):
        M, f = self.mass_and_forcing(time, *q, *u, *(p[k] for k in self.params))
        return np.array(M, dtype=float), np.array(f, dtype=float).reshape(-1)

    def accelerations(self, time, q, u, p) -> np.ndarray:
        M, f = self.numeric(time, q, u, p)
        return np.linalg.solve(M, f)

    def integrate(self, p: dict[str, float], y0: Sequence[float], t_eval: np.ndarray):
        """Our own integration: DOP853 at rtol 1e-12 on our own equations."""
        n = len(self.names)

        def rhs(time, y):
            return np.concatenate([y[n:], self.accelerations(time, y[:n], y[n:], p)])

        sol = solve_ivp(
            rhs,
            (t_eval[0], t_eval[-1]),
            y0,
            method="DOP853",
            t_eval=t_eval,
            rtol=1e-12,
            atol=1e-13,
        )
        assert sol.success, sol.message
        return sol.y


def symbols(names: str) -> list[sp.Symbol]:
    return list(sp.symbols(names, real=True))


def moving_point(name: str, frame: ReferenceFrame, r: Vector) -> Point:
    """A point whose velocity in the inertial frame is dr/dt, for LagrangesMethod's loads."""
    P = Point(name)
    P.set_vel(frame, r.dt(frame))
    return P


def lagranges_reference(
    L: sp.Expr,
    q: list,
    params: list[sp.Symbol],
    frame: ReferenceFrame,
    loads: Sequence[tuple] = (),
) -> Reference:
    """sympy's LagrangesMethod on our own L and loads, lambdified in (t, q, u, params)."""
    lm = LagrangesMethod(L, q, forcelist=list(loads) or None, frame=frame)
    lm.form_lagranges_equations()
    return _lambdified(lm.mass_matrix, lm.forcing, q, params)


def _lambdified(M: sp.Matrix, f: sp.Matrix, q: list, params: list[sp.Symbol]) -> Reference:
    qs = [sp.Symbol(f"q_{i}") for i in range(len(q))]
    us = [sp.Symbol(f"u_{i}") for i in range(len(q))]
    ts = sp.Symbol("t_")
    subs = {qi.diff(t): ui for qi, ui in zip(q, us, strict=True)}
    subs |= dict(zip(q, qs, strict=True))
    subs[t] = ts
    M, f = M.xreplace(subs), f.xreplace(subs)
    fn = sp.lambdify([ts, *qs, *us, *params], [M, f], modules="numpy", cse=True)
    names = [str(qi.func) for qi in q]
    return Reference(names, [str(s) for s in params], fn)


def engine_reference(mass_matrix: sp.Matrix, forcing: sp.Matrix, names, params) -> Reference:
    """The engine's M and f, with every function, derivative and parameter matched by name."""
    qs = {n: sp.Symbol(f"q__{n}") for n in names}
    us = {n: sp.Symbol(f"u__{n}") for n in names}
    ps = {n: sp.Symbol(f"p__{n}") for n in params}
    ts = sp.Symbol("t__")
    both = sp.Matrix.hstack(mass_matrix, forcing)
    subs: dict = {}
    for d in both.atoms(sp.Derivative):
        name, order = str(d.expr.func), d.derivative_count
        assert order == 1, f"the engine's M or f holds {d}"
        subs[d] = us[name]
    for fn in both.atoms(AppliedUndef):
        subs[fn] = qs[str(fn.func)]
    for s in both.free_symbols:
        if str(s) == "t":
            subs[s] = ts
        elif str(s) in ps:
            subs[s] = ps[str(s)]
        else:
            raise AssertionError(f"unknown symbol {s} in the engine's M or f")
    M, f = mass_matrix.xreplace(subs), forcing.xreplace(subs)
    args = [ts, *qs.values(), *us.values(), *ps.values()]
    fn = sp.lambdify(args, [M, f], modules=[{"sign": np.sign, "Abs": np.abs}, "numpy"])
    return Reference(list(names), list(params), fn)


def linear_modes(ref: Reference, q0, p, time: float = 0.0, h: float = 1e-6):
    """Our own linearization at rest (central differences): growth rate and frequencies.

    The first-order matrix [[0, I], [−M⁻¹K, −M⁻¹C]] keeps gyroscopic (Coriolis) coupling, which a
    K v = ω² M v eigenproblem alone would drop.
    """
    n = len(q0)
    q0 = np.asarray(q0, dtype=float)
    zero = np.zeros(n)
    M, _ = ref.numeric(time, q0, zero, p)
    K = np.empty((n, n))
    C = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        K[:, k] = -(ref.numeric(time, q0 + e, zero, p)[1] - ref.numeric(time, q0 - e, zero, p)[1])
        C[:, k] = -(ref.numeric(time, q0, e, p)[1] - ref.numeric(time, q0, -e, p)[1])
    K /= 2 * h
    C /= 2 * h
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam = np.linalg.eigvals(A)
    growth = float(np.max(lam.real))
    freqs = sorted(float(x) for x in lam.imag if x > 1e-6)
    return growth, freqs
