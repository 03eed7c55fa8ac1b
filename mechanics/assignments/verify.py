"""Every key checked by a second route before a student sees it.

The key comes from the engine's derivation (mechanics/derive.py: its own velocities, energies,
partial derivatives, simplification). The second route is sympy's own mechanics, as the tests'
oracle (mechanics/oracle.py) uses it: T from each body's ``kinetic_energy`` (sympy.physics.
mechanics), V written out from the spec's fields, Q_j from sympy's velocities of the loads' points,
and the equations of motion from ``LagrangesMethod``. The two share only the model's bodies,
positions and declared loads; they are then compared by sympy's simplification (not by the
checker's proofs, which would be the same code judging itself): a difference that is non-zero at a
sampled state is a disagreement, one that sympy cannot reduce to zero is "cannot confirm", and a
variant with either is never deployed (the preview says why).
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from typing import Any

import sympy as sp

from mechanics.derive import Derivation
from mechanics.model import T as t

from . import second_route

#: Past this many operations sympy's general simplify() is not tried (it can take minutes).
SIMPLIFY_OPS = 600
SAMPLES = 6
TOLERANCE = 1e-8
HUGE = 10**4


@dataclass(frozen=True)
class Check:
    """The second route's word on one key: ``status`` is "verified", "disagrees" or
    "unconfirmed", and ``why`` says so in a sentence."""

    status: str
    why: str

    @property
    def ok(self) -> bool:
        return self.status == "verified"


class _Oracle:
    """The quantities of one derivation's model, by sympy.physics.mechanics alone (lazily)."""

    def __init__(self, d: Derivation) -> None:
        self.m = d.model
        self._lm: Any = None

    def T(self) -> sp.Expr:
        return sp.Add(*(b.sympy_body.kinetic_energy(self.m.N) for b in self.m.bodies))

    def V(self) -> sp.Expr:
        return second_route.potential(self.m)

    def L(self) -> sp.Expr:
        return self.T() - self.V()

    def Q(self, j: int) -> sp.Expr:
        """Σ F·∂v_P/∂q̇_j + Σ τ·∂ω/∂q̇_j over the declared loads (dampers and forces)."""
        N, qd = self.m.N, self.m.qd[j]
        total = sp.S.Zero
        for where, vector in second_route.loads(self.m):
            if isinstance(where, sp.physics.vector.ReferenceFrame):
                rate = where.ang_vel_in(N)
            else:
                rate = where.vel(N)
            total += vector.dot(rate.diff(qd, N))
        return total

    def lagranges(self) -> Any:
        if self._lm is None:
            self._lm = second_route.lagranges_method(self.m)
        return self._lm

    def eom(self, j: int) -> sp.Expr:
        return self.lagranges().eom[j]

    def momentum(self, j: int) -> sp.Expr:
        return self.L().diff(self.m.qd[j])


def _plain(expr: sp.Expr, model: Any) -> sp.Expr:
    """q(t), q̇, q̈ as plain real symbols (highest derivative first), parameters positive where
    their value is: sympy then reads √(l²) as l, as the engine does for a length."""
    swap: dict[Any, Any] = {}
    for i, (qd, qdd) in enumerate(zip(model.qd, model.qdd, strict=True)):
        swap[qdd] = sp.Symbol(f"_qdd{i}", real=True)
        swap[qd] = sp.Symbol(f"_qd{i}", real=True)
    out = expr.subs(swap)
    out = out.subs({q: sp.Symbol(f"_q{i}", real=True) for i, q in enumerate(model.q)})
    positive = {
        sym: sp.Symbol(sym.name, positive=True)
        for name, sym in model.params.items()
        if model.spec.parameters.get(name, 0) > 0
    }
    return out.xreplace(positive)


def _branch_roots(expr: sp.Expr, state: dict) -> sp.Expr:
    """√(p²) as |p| read on the side the scene starts on (p's sign at the spec's own state): the
    engine derives a spring along a line on that side (mechanics/model.py), so must the check."""
    swap = {}
    for root in expr.atoms(sp.Pow, sp.Abs):
        if isinstance(root, sp.Abs):
            inner = root.args[0]
        elif root.exp == sp.Rational(1, 2) and (base := sp.factor(root.base)).is_Pow:
            if base.exp != 2:
                continue
            inner = base.base
        else:
            continue
        try:
            sign = 1 if complex(inner.xreplace(state)).real >= 0 else -1
        except TypeError:
            continue
        swap[root] = sign * inner
    return expr.xreplace(swap)


def _states(model: Any, plain_syms: set[sp.Symbol], rng: random.Random) -> list[dict]:
    """States near the spec's own (its parameters, its initial values), where the model holds."""
    spec = model.spec
    out = []
    for k in range(SAMPLES):
        state: dict[sp.Symbol, Any] = {}
        spread = 0 if k == 0 else 1
        for s in plain_syms:
            name = s.name
            if name.startswith("_q") and not name.startswith("_qd"):
                i = int(name[2:])
                start = spec.initial.get(spec.coordinates[i], 0.0) or 0.3
                value = start + spread * rng.uniform(-0.1, 0.1) * (abs(start) or 1)
            elif name.startswith("_qd"):
                value = rng.uniform(-2, 2)
            elif s == t:
                value = rng.uniform(0, 3)
            else:
                default = spec.parameters.get(name, 1.0)
                value = (default or 1.0) * (1 + spread * rng.uniform(-0.2, 0.2))
            state[s] = sp.Float(value, 30)
        out.append(state)
    return out


def zero(diff: sp.Expr, model: Any, constant: bool = False) -> Check:
    """Is ``diff`` (the engine's key minus the second route's) zero (or, ``constant``, free of
    the motion)? Sampled first (a disagreement is named), then proved by sympy."""
    plain = _plain(diff, model)
    rng = random.Random(27)
    states = _states(model, plain.free_symbols | {t}, rng)
    plain = _branch_roots(plain, states[0])
    if constant:
        moving = [s for s in plain.free_symbols if s.name.startswith("_q") or s == t]
        parts = [plain.diff(s) for s in moving]
    else:
        parts = [plain]
    for part in parts:
        for state in states:
            try:
                value = complex(part.xreplace(state).evalf(25))
            except (TypeError, ValueError, ArithmeticError):
                continue
            if abs(value) > TOLERANCE:
                return Check(
                    "disagrees",
                    f"the engine's key and sympy's LagrangesMethod differ by {abs(value):.3g} "
                    "at a sampled state",
                )
    for part in parts:
        if not _proved_zero(part):
            return Check(
                "unconfirmed",
                "the two routes agree at every sampled state, but sympy could not show the "
                "difference is zero",
            )
    return Check("verified", "equal to sympy's LagrangesMethod route, proved by sympy")


def _huge(expr: sp.Expr) -> bool:
    """Numbers past HUGE make sympy's polynomial algebra explode (exp(−10⁶ θ̇²) read as a power
    10⁶ of one generator): such a difference is not proved, it is "cannot confirm"."""
    return any(abs(n) > HUGE for n in expr.atoms(sp.Number) if n.is_finite)


def _proved_zero(expr: sp.Expr) -> bool:
    if _huge(expr):
        return sp.expand(expr) == 0
    tries = (
        lambda e: e,
        sp.expand,
        lambda e: sp.cancel(sp.expand(e)),
        lambda e: sp.expand(sp.expand_trig(e)),
        lambda e: sp.trigsimp(sp.expand(e)),
    )
    for attempt in tries:
        if attempt(expr) == 0:
            return True
    return sp.count_ops(expr) <= SIMPLIFY_OPS and sp.simplify(expr) == 0


def verify_key(d: Derivation, quantity: str, j: int | None, engine: sp.Expr) -> Check:
    """Compare one part's key (the engine's expected expression, as mechanics.check judges
    against) with the same quantity from the second route."""
    o = _Oracle(d)
    m = d.model
    if quantity == "T":
        return zero(engine - o.T(), m)
    if quantity == "V":
        return zero(engine - o.V(), m, constant=True)
    if quantity == "L":
        return zero(engine - o.L(), m, constant=True)
    if quantity == "Q":
        return zero(engine - o.Q(j), m)  # type: ignore[arg-type]
    if quantity == "eom":
        return zero(engine - o.eom(j), m)  # type: ignore[arg-type]
    if quantity == "momentum":
        return zero(engine - o.momentum(j), m)  # type: ignore[arg-type]
    if quantity == "accel":
        # q̈_j from the engine put into sympy's M q̈ = f: every row must then hold, with the
        # other accelerations the engine's too (solving would share nothing new)
        lm = o.lagranges()
        solved = dict(zip(m.qdd, d.solved_accelerations, strict=True))
        solved[m.qdd[j]] = engine
        residual = (lm.mass_matrix * sp.Matrix(m.qdd) - lm.forcing).xreplace(solved)
        for row in residual:
            check = zero(row, m)
            if not check.ok:
                return check
        return check
    return Check("unconfirmed", f"no second route for '{quantity}'")
