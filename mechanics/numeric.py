"""Derivation -> fast numeric functions, compiled once per scene, parameters as run-time arguments.

The right-hand side is what an integrator calls tens of thousands of times, so it is generated as
scalar `math` code with common subexpressions eliminated (lambdify cse=True): a few µs per call,
where numpy on scalars costs several times that. Everything evaluated along a finished trajectory
(energies, positions, frame axes) is generated for numpy arrays instead, evaluated once per run.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp
from sympy.physics.vector import Vector

from mechanics import native
from mechanics.derive import Derivation, derivation_of_scene, derivation_of_spec, spec_text
from mechanics.model import StopInfo
from mechanics.model import T as t
from mechanics.spec import SpecError
from mechanics.steps import partial
from mechanics.steps.conserved import explicit_time
from mechanics.steps.energy import potential_parts
from mechanics.steps.fbd import body_forces


def _sign(x: float) -> float:
    return (x > 0) - (x < 0)


_MATH = [{"sign": _sign, "Abs": abs}, "math"]
_NUMPY = [{"sign": np.sign, "Abs": np.abs}, "numpy"]


@dataclass
class StopFunction:
    """A stop condition compiled for arrays and scalars: value(t, q, q̇, p) > 0 while it holds."""

    name: str
    message: str
    crossing: str  # "falls" | "any"
    value: Any
    only_if: Any | None = None
    kind: str = "declared"  # see mechanics.model.StopInfo.kind


@dataclass
class CompiledScene:
    """Numeric twins of a derivation; every function takes (t, *q, *q_dot, *params)."""

    derivation: Derivation
    coordinates: list[str]
    parameters: list[str]
    nonnegative: set[str]
    accel_and_power: Any  # scalar: -> (q̈_1..q̈_n, P_NC)
    mass_and_forcing: Any  # scalar, n > 3: -> (M flat, f)
    energy: Any  # arrays: -> (T, V)
    jacobi: Any | None  # arrays: h, when the Jacobi integral (not E) is conserved
    momenta: dict[str, Any]  # arrays: conserved p_j of cyclic coordinates
    mass_matrix: Any  # arrays or scalars: -> M flat (for the singularity check)
    powers: dict[str, Any]  # arrays: power F·v of each non-conservative force (or M·ω)
    potential_parts: dict[str, Any]  # arrays: each conservative force's share of V
    forces: list[tuple[str, str, str, Any]]  # (label, kind, on, arrays -> x, y, z in N)
    places: dict[str, Any]  # arrays: -> (x, y, z) of each point/body
    frames: dict[str, Any]  # arrays: -> 9 components of the frame's axes in N
    solved: bool  # True: q̈ from the symbolic solution; False: M q̈ = f solved numerically
    native_inputs: dict[str, Any]  # rhs_source's arguments: the same expressions, for C
    #: Extra states after q, q̇: W_NC, and W_t = ∫ −∂L/∂t dt when L depends on t explicitly.
    extras: int = 1
    #: arrays: E − h = T₁ + 2T₀, so the drive's work is W_drive = Δ(E − h) + W_t. None when the
    #: constraints do not move and L has no explicit t (nothing drives the system).
    drive: Any | None = None
    #: arrays: p of each branched spring (ℓ = p on the side it was derived for), by spring index.
    branch_values: dict[int, Any] = field(default_factory=dict)
    stop_specs: list[Any] = field(default_factory=list)  # model StopInfo, compiled on first use

    @property
    def n(self) -> int:
        return len(self.coordinates)

    @functools.cached_property
    def native_source(self) -> str:
        """The right-hand side as C (generated on first use: most scenes never need it)."""
        return native.rhs_source(**self.native_inputs)

    def native_rhs(self, params: list[float]) -> native.NativeRhs:
        """The compiled twin of `rhs(params)`; raises NativeUnavailable when it cannot be built."""
        return native.compile_rhs(self.native_source, params, 2 * self.n + self.extras)

    @functools.cached_property
    def stops(self) -> list[StopFunction]:
        """The stop conditions as functions (a string's tension needs Newton's method: compiled
        only for scenes that declare one)."""
        args, subs = _args(self.derivation)
        out = []
        for i, st in enumerate(self.stop_specs):
            if st.tension is not None:
                force, tension = constraint_force_functions(self).get(st.tension, (None, None))
                value = _along(force, st.along) if st.along is not None and force else tension
                if value is None:
                    raise SpecError(
                        [
                            {
                                "field": f"stops[{i}].tension",
                                "message": f"'{st.tension}' hangs on no string or rod whose "
                                "tension Newton's method can name",
                            }
                        ]
                    )
            else:
                value = sp.lambdify(args, [_plain(st.when, subs)], modules=_NUMPY)
            guard = None
            if st.only_if is not None:
                guard = sp.lambdify(args, [_plain(st.only_if, subs)], modules=_NUMPY)
            out.append(StopFunction(st.name, st.message, st.crossing, value, guard, st.kind))
        return out

    def rhs(self, params: list[float]):
        """dy/dt for y = [q, q̇, W_NC (, W_t)]: the work of the non-conservative forces (and of
        the explicit time dependence of L) rides along."""
        n = self.n
        p = tuple(params)
        if self.solved:
            f = self.accel_and_power

            def rhs(time: float, y: np.ndarray) -> np.ndarray:
                state = y.tolist()  # Python floats: math functions on numpy scalars are slow
                try:
                    return np.array(state[n : 2 * n] + f(time, *state[: 2 * n], *p))
                except ValueError:  # math.sqrt(−1): past a domain's end, as numpy and C say
                    return np.full(len(state), np.nan)

            return rhs
        mf, power = self.mass_and_forcing, self.accel_and_power

        def rhs(time: float, y: np.ndarray) -> np.ndarray:
            args = (time, *y.tolist()[: 2 * n], *p)
            try:
                values = np.asarray(mf(*args), dtype=float)
                rates = power(*args)
            except ValueError:  # math.sqrt(−1): past a domain's end, as numpy and C say
                return np.full(len(y), np.nan)
            out = np.empty(2 * n + self.extras)
            out[:n] = y[n : 2 * n]
            out[n : 2 * n] = np.linalg.solve(values[: n * n].reshape(n, n), values[n * n :])
            out[2 * n :] = rates
            return out

        return rhs


def _along(force: Any, unit: tuple[float, float, float]) -> Any:
    """R·ê of a compiled constraint force (x, y, z in N): a string's tension along ê."""

    def value(*args: Any) -> list[Any]:
        x, y, z = force(*args)
        return [unit[0] * np.asarray(x) + unit[1] * np.asarray(y) + unit[2] * np.asarray(z)]

    return value


def _args(d: Derivation) -> tuple[list, dict]:
    m = d.model
    q = [sp.Symbol(f"q_{i}") for i in range(len(m.q))]
    u = [sp.Symbol(f"u_{i}") for i in range(len(m.q))]
    ts = sp.Symbol("t_")
    subs = dict(zip(m.qd, u, strict=True)) | dict(zip(m.q, q, strict=True))
    subs[t] = ts
    params = [m.params[name] for name in m.spec.parameters]
    return [ts, *q, *u, *params], subs


def _plain(expr: Any, subs: dict) -> Any:
    """q(t), q̇(t), t -> plain symbols: derivatives first, so q̇ is not read as d/dt of a number.

    δ(u) -> 0: sympy's d sign(u)/du = 2δ(u) has no numeric twin in Python, numpy or C, and is 0
    wherever u ≠ 0; `refuse_impulses` has already refused the scenes where δ carries weight (a
    potential that jumps), so only the terms that vanish on u = 0 (u δ(u), from u·sign(u)) reach
    here."""
    if not isinstance(expr, sp.Basic):
        return sp.Float(expr)
    out = expr.xreplace(subs)
    return out.replace(sp.DiracDelta, lambda *_: sp.S.Zero) if out.has(sp.DiracDelta) else out


def _vanishes_where_zero(coefficient: sp.Expr, u: sp.Expr) -> bool:
    """True when ``coefficient`` is 0 wherever u = 0 (so coefficient·δ(u) = 0 as a force).
    Decided only for u of degree ≤ 2 in one of its symbols; anything else counts as weight."""
    for s in sorted(u.free_symbols, key=str):
        try:
            poly = sp.Poly(u, s)
        except sp.PolynomialError:
            continue
        if not 1 <= poly.degree() <= 2 or poly.has(sp.DiracDelta):
            continue
        roots = sp.solve(u, s)
        return bool(roots) and all(sp.simplify(coefficient.xreplace({s: r})) == 0 for r in roots)
    return False


def refuse_impulses(d: Derivation, exprs: list) -> None:
    """A potential that jumps (k·sign(x)) makes its force an impulse 2kδ(x): no integrator
    follows it (δ is 0 at every step it samples, so the particle would cross the step as if it
    were not there and V would jump). Refused naming the potential; u·sign(u) = |u| is smooth
    enough (its δ term u δ(u) is 0) and passes."""
    z = sp.Dummy("z")
    for e in exprs:
        if isinstance(e, sp.Basic) and e.has(sp.Derivative):
            e = e.doit()  # ∂/∂t sign(t − 1) stays unevaluated in sympy: 2δ(t − 1)
            if e.has(sp.Derivative):
                raise SpecError([_impulse_error(d, None)])
        if not isinstance(e, sp.Basic) or not e.has(sp.DiracDelta):
            continue
        for delta in e.atoms(sp.DiracDelta):
            u = delta.args[0]
            ordinary = len(delta.args) == 1 or delta.args[1] == 0
            weight = sp.diff(e.xreplace({delta: z}), z)
            if ordinary and _vanishes_where_zero(weight, u):
                continue
            raise SpecError([_impulse_error(d, u)])


def _impulse_error(d: Derivation, u: sp.Expr | None) -> dict[str, str]:
    m = d.model
    args, _ = _args(d)
    names = [sp.Symbol("t"), *(sp.Symbol(c) for c in m.coordinate_names)]
    where = (
        ""
        if u is None
        else f" where {sp.sstr(u.xreplace(dict(zip(args, names, strict=False))))} = 0"
    )
    fields = [
        f"potentials[{i}].expression" for i, (_, v) in enumerate(m.potentials) if v.has(sp.sign)
    ]
    return {
        "field": ", ".join(fields) or "potentials",
        "message": f"this potential jumps{where} (sign() of a coordinate or of t, not multiplied "
        "by something that vanishes there): its force is an impulse at the jump, which no "
        "integrator can follow; write it without the jump (abs(x) and x*sign(x) are continuous)",
    }


def compile_derivation(d: Derivation) -> CompiledScene:
    m, w = d.model, d.work
    args, subs = _args(d)

    def scalar(exprs: list) -> Any:
        return sp.lambdify(args, [_plain(e, subs) for e in exprs], modules=_MATH, cse=True)

    def vector(exprs: list) -> Any:
        return sp.lambdify(args, [_plain(e, subs) for e in exprs], modules=_NUMPY, cse=True)

    power = sum((Q * qd for Q, qd in zip(w.Q, m.qd, strict=True)), sp.S.Zero)
    rates = [power]
    if explicit_time(w.L, m):
        rates.append(-partial(w.L, t, m))  # dh/dt = Σ Q_j q̇_j − ∂L/∂t (notes III)
    # E − h = T₁ + 2T₀ vanishes unless constraints move (T not quadratic in q̇): the drive's work
    # W_drive = ΔE − W_NC = Δ(E − h) + W_t, since dh/dt = P_NC − ∂L/∂t.
    h = sum((qd * p for qd, p in zip(m.qd, w.momenta, strict=True)), sp.S.Zero) - w.L
    drive = sp.expand(w.T + w.V - h)
    if drive == 0 and len(rates) == 1:
        drive = None
    solved = w.accelerations is not None
    equations = list(w.accelerations) if solved else [*w.mass_matrix, *w.forcing]
    refuse_impulses(d, [e.xreplace(subs) for e in [*equations, *rates] if isinstance(e, sp.Basic)])
    native_inputs = {"args": args, "n": len(m.q), "power": [_plain(r, subs) for r in rates]}
    if solved:
        native_inputs["accelerations"] = [_plain(e, subs) for e in w.accelerations]
    else:
        native_inputs["mass"] = [_plain(e, subs) for e in w.mass_matrix]
        native_inputs["forcing"] = [_plain(e, subs) for e in w.forcing]
    if solved:
        accel_and_power = scalar([*w.accelerations, *rates])
        mass_and_forcing = None
    else:
        accel_and_power = scalar(rates)
        mass_and_forcing = scalar([*w.mass_matrix, *w.forcing])
    jacobi = next((c["expr"] for c in w.conserved if c["name"] == "jacobi"), None)
    powers = {}
    for load in m.loads:
        if load.kind == "torque":
            body = next(b for b in m.bodies if b.name == load.on)
            rate = body.frame.ang_vel_in(m.N)
        else:
            rate = m.velocity(load.on)
        if rate == Vector(0):
            continue  # a force on a fixed point (a damper's wall end) does no work
        key = f"{load.kind}:{load.name}" + (f"@{load.on}" if load.kind == "damper" else "")
        powers[key] = powers.get(key, sp.S.Zero) + load.vector.dot(rate)
    powers = {k: vector([p]) for k, p in powers.items()}
    parts = {f"{kind}:{name}": vector([e]) for kind, name, e in potential_parts(m)}
    forces = [
        (label, kind, on, vector([vec.dot(u) for u in (m.N.x, m.N.y, m.N.z)]))
        for on, acting in body_forces(m).items()
        for label, kind, vec in acting
        if on in {b.name for b in m.bodies}
    ]
    places = {
        name: vector([r.dot(u) for u in (m.N.x, m.N.y, m.N.z)]) for name, r in m.positions.items()
    }
    frames = {
        name: vector([getattr(f.frame, a).dot(u) for a in "xyz" for u in (m.N.x, m.N.y, m.N.z)])
        for name, f in m.frames.items()
    }
    return CompiledScene(
        derivation=d,
        coordinates=m.coordinate_names,
        parameters=list(m.spec.parameters),
        nonnegative={k for k, s in m.params.items() if s.is_nonnegative},
        accel_and_power=accel_and_power,
        mass_and_forcing=mass_and_forcing,
        energy=vector([w.T, w.V]),
        jacobi=None if jacobi is None else vector([jacobi]),
        momenta={
            c["coordinate"]: vector([c["expr"]]) for c in w.conserved if c["name"] == "momentum"
        },
        mass_matrix=vector(list(w.mass_matrix)),
        powers=powers,
        potential_parts=parts,
        forces=forces,
        places=places,
        frames=frames,
        solved=solved,
        native_inputs=native_inputs,
        extras=len(rates),
        drive=None if drive is None else vector([drive]),
        branch_values={
            i: vector([s.branch]) for i, s in enumerate(m.springs) if s.branch is not None
        },
        stop_specs=[*m.stops, *sticking_stops(d)],
    )


def velocity_jumps(d: Derivation) -> list[sp.Expr]:
    """The arguments u of sign(u) in the equations of motion that hold a velocity (Coulomb
    friction −μ m g sign(ẋ)): where u = 0 the force jumps, and the equations' sign(0) = 0 is
    a model of sliding only."""
    m, w = d.model, d.work
    exprs = list(w.accelerations) if w.accelerations is not None else list(w.forcing)
    exprs = [e for e in exprs if isinstance(e, sp.Basic)]
    _, subs = _args(d)
    found: list[sp.Expr] = []
    for e in exprs:
        for atom in e.atoms(sp.sign):
            u = atom.args[0]
            if not u.has(*m.qd) or u in found:
                continue
            jumps = [_plain(x.xreplace({atom: 1}) - x.xreplace({atom: -1}), subs) for x in exprs]
            if any(j != 0 and not _vanishes_where_zero(j, _plain(u, subs)) for j in jumps):
                found.append(u)  # not quadratic drag c·sign(ẋ)·ẋ², nor sign(ẋ)·|ẋ| = ẋ
    return found


def sticking_stops(d: Derivation) -> list[StopInfo]:
    """Implicit stops where a sliding contact sticks: u (a velocity inside sign(u)) reaches 0
    while the other forces cannot overcome the friction, that is while u̇ computed with
    sign(u) = +1 is ≤ 0 and with sign(u) = −1 is ≥ 0 (each side pushes back to u = 0).

    There the equations (sign(0) = 0) no longer describe the contact: an integrator chatters
    across u = 0 in ever smaller steps (DOP853 crawled to t = 3e-5 s, Radau to 2e-11 s, in 10 s
    of server time) and what it shows is no motion. Only for equations solved for q̈, and not
    where the spec declares a sign-change stop of its own (the block on the incline does)."""
    m, w = d.model, d.work
    if w.accelerations is None or any(
        st.crossing == "any" and st.kind == "declared" for st in m.stops
    ):
        return []
    out = []
    for u in velocity_jumps(d):
        rate = u.diff(t)
        sides = []
        for side in (1, -1):
            qdd = [a.xreplace({sp.sign(u): side}) for a in w.accelerations]
            sides.append(rate.xreplace(dict(zip(m.qdd, qdd, strict=True))))
        if any(s.has(sp.Derivative) for s in sides):
            continue
        text = sp.sstr(_plain(u, _user_names(d)))
        out.append(
            StopInfo(
                f"sticks_{text}",
                f"{text} reaches 0 where the other forces cannot overcome the friction "
                f"(sign({text}) jumps there): the contact sticks, and the equations, read with "
                "sign(0) = 0, describe it only while it slides, so the model ends",
                u,
                crossing="any",
                only_if=sp.Min(-sides[0], sides[1]),
                kind="sticks",
            )
        )
    return out


def velocity_jump_functions(c: CompiledScene) -> list[tuple[str, Any]]:
    """(u as the spec writes it, u(t, q, q̇, p) for scalars) for each sign(u) of a velocity in
    the equations: where a run starting at u = 0 sits on the jump."""
    cached = getattr(c, "_velocity_jumps", None)
    if cached is None:
        args, subs = _args(c.derivation)
        cached = [
            (sp.sstr(_plain(u, _user_names(c.derivation))), sp.lambdify(args, _plain(u, subs)))
            for u in velocity_jumps(c.derivation)
        ]
        c._velocity_jumps = cached
    return cached


def _user_names(d: Derivation) -> dict:
    """q(t), q̇(t) -> the names the spec uses (x, x_dot), for a message."""
    m = d.model
    names = {qd: sp.Symbol(f"{c}_dot") for qd, c in zip(m.qd, m.coordinate_names, strict=True)}
    return names | {q: sp.Symbol(c) for q, c in zip(m.q, m.coordinate_names, strict=True)}


def constraint_force_functions(c: CompiledScene) -> dict[str, tuple[Any, Any | None]]:
    """Per body: R in N components, and the rod tension when there is one (compiled on demand:
    Newton's method costs seconds for a double pendulum, and most runs never ask)."""
    cached = getattr(c, "_constraint_forces", None)
    if cached is None:
        from mechanics.newton import newton

        m = c.derivation.model
        args, subs = _args(c.derivation)
        _, forces, _ = newton(c.derivation)
        cached = {}
        for f in forces:
            comps = [_plain(f.vector.dot(u), subs) for u in (m.N.x, m.N.y, m.N.z)]
            fn = sp.lambdify(args, comps, modules=_NUMPY, cse=True)
            tension = None
            if f.support is not None:
                tension = sp.lambdify(args, [_plain(f.support[1], subs)], modules=_NUMPY)
            cached[f.body] = (fn, tension)
        c._constraint_forces = cached
    return cached


Branches = tuple[tuple[int, int], ...]


@functools.lru_cache(maxsize=64)
def compiled_scene(scene_id: str, branches: Branches = ()) -> CompiledScene:
    """A built-in scene compiled once per process; a slider change only changes the arguments.
    ``branches`` asks for the variant with springs on other sides of their anchors."""
    return compile_derivation(derivation_of_scene(scene_id, branches))


@functools.lru_cache(maxsize=32)
def _compiled_spec(text: str, branches: Branches = ()) -> CompiledScene:
    return compile_derivation(derivation_of_spec(text, branches))


def compiled_spec(spec: dict, branches: Branches = ()) -> CompiledScene:
    """A posted spec compiled once per distinct spec (keyed by its canonical JSON), from the same
    derivation its derive, check and equilibria requests use."""
    return _compiled_spec(spec_text(spec), branches)


#: Past 1e±30 a value is more likely a units mistake than physics: such values are named first
#: when a scene's numbers overflow double precision.
EXTREME_EXPONENT = 30


def overflow_error(values: dict[str, float], fallback: list[str], what: str) -> dict[str, str]:
    """The 422 entry for numbers past double precision (``what`` says what broke, verb included):
    names the values (keyed by field path) farthest from 1 in order of magnitude, or the
    ``fallback`` fields when none is extreme."""
    far = [
        (k, v) for k, v in values.items() if v != 0 and abs(math.log10(abs(v))) > EXTREME_EXPONENT
    ]
    far.sort(key=lambda kv: -abs(math.log10(abs(kv[1]))))
    advice = "pick units in which the numbers are nearer 1"
    if not far:
        return {"field": ", ".join(fallback) or "parameters", "message": f"{what}: {advice}"}
    named = ", ".join(f"{k.rsplit('.', 1)[-1]} = {v:g}" for k, v in far)
    return {"field": ", ".join(k for k, _ in far), "message": f"with {named}, {what}: {advice}"}


def evaluate(fn: Any, time: np.ndarray, q: np.ndarray, qd: np.ndarray, params: list[float]):
    """Evaluate an array function along a trajectory; constants broadcast to the time axis.

    Parameters go in as numpy floats: a product of parameters alone (m·l² with l = 1e155) is not
    an array, and Python floats raise OverflowError where numpy gives inf. A value too large for
    a double is inf or nan in the result, for the caller to refuse or flag, never an exception.
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        out = fn(time, *q, *qd, *(np.float64(p) for p in params))
    return [np.broadcast_to(np.asarray(v, dtype=float), time.shape) for v in out]
