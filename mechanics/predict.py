"""What a student's answer predicts: its motion beside the true one, from the same initial state.

A wrong equation of motion is easier to believe wrong when it is seen to move wrong. From the
answer (read by the same whitelist parser as the check) the student's model is built as a set of
equations linear in q̈, one per coordinate:

- ``eom``: the student's equation for coordinate j, the derived ones for the others;
- ``accel``: q̈_j − (the student's q̈_j) = 0, the derived equations for the others;
- ``T``, ``V``, ``L``: Lagrange's equations of L' = T' − V, T − V' or L' (notes eq. 31), with the
  scene's own non-conservative Q;
- ``Q``: the derived left-hand sides with the student's Q_j.

Both models, the true one through the very same code, are integrated with DOP853 (rtol 1e-9)
from the scene's initial state for a few seconds under a wall-time and step cap. The report:
both trajectories (q, q̇, the positions and frame axes for drawing), the time they part visibly
(a stated rule), and the energy of each run measured with the TRUE E(q, q̇) = T + V, so an answer
that creates or destroys energy says how much.

Each run ends at the scene's stops, as a /simulate run does (mechanics/stops.py watches and
locates them): the answer changes the dynamics, not the geometry, so a mass reaching the pulley
ends the answer's motion as it ends the true one. Past a stop the model does not hold, so every
comparison (parting, energies, the drawing) covers only the time both motions exist; an Atwood
machine integrated 5 s past its pulley had its masses fly 80 m through it, and its "largest
kinetic energy" came from there (instructor play-test).

An answer that cannot be integrated (no q̈ in it, q̈ not linear, its q̈ undetermined at the
initial state) is refused as an ExprError on ``answer``; one that blows up during the run is a
result (``student.blew_up_at``), not an error.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp
from scipy.integrate import DOP853, solve_ivp
from scipy.optimize import brentq

from mechanics import units
from mechanics.answers import read_answer
from mechanics.check import check, expected_quantity, scene_dimensions
from mechanics.derive import Derivation
from mechanics.expr import ExprError, to_latex
from mechanics.model import T as t
from mechanics.model import physical_limit_errors
from mechanics.numeric import _MATH, _NUMPY, StopFunction, _args, _plain, compile_derivation
from mechanics.spec import SpecError
from mechanics.steps import partial
from mechanics.stops import StopWatch, refuse_passed_stops, stopped_at_start

PREDICTED = ("T", "V", "L", "Q", "eom", "accel")
T_END, MAX_T_END = 5.0, 10.0
SAMPLES_PER_SECOND = 60
MAX_SAMPLES = 601
MAX_STEPS = 20_000
RUN_SECONDS = 2.0  # wall time of one run; the pool's budget bounds the whole job
RTOL = ATOL = 1e-9
#: |q| or |q̇| past this is a blow-up: no teaching scene moves 10⁶ rad or m, or at 10⁶ per s
BLOW_UP = 1e6
#: The runs have parted visibly when some body is this fraction of the scene's size away from
#: where it truly is (scenes without moving bodies: a coordinate off by PART_COORDINATE).
PART_FRACTION = 0.02
PART_COORDINATE = 0.05


_SINGULAR = "its accelerations are not determined there (their coefficients vanish)"
_INFINITE = "its accelerations are not finite"
_DOMAIN = "it leaves the domain of a function (a root of a negative, …)"


class _Stop(Exception):
    """The right-hand side cannot go on: the student's q̈ is singular or not finite here."""

    def __init__(self, why: str) -> None:
        super().__init__(why)
        self.why = why


@dataclass
class Run:
    t: np.ndarray
    y: np.ndarray  # samples × 2n: q then q̇
    reached: float  # how far the stepping got
    blew_up_at: float | None = None
    why: str = ""  # why it stopped early, in words
    stopped_at: float | None = None  # when it reached one of the scene's stops (why: its message)


def equations(d: Derivation, quantity: str, given: sp.Expr, j: int | None) -> list[sp.Expr]:
    """The student's model as expressions that vanish along its motion, one per coordinate."""
    m, w = d.model, d.work
    true = [w.eom_lhs[k] - w.Q[k] for k in range(len(m.q))]
    if quantity == "eom":
        return [given if k == j else e for k, e in enumerate(true)]
    if quantity == "accel":
        return [m.qdd[k] - given if k == j else e for k, e in enumerate(true)]
    if quantity == "Q":
        return [w.eom_lhs[k] - (given if k == j else w.Q[k]) for k in range(len(m.q))]
    lagrangian = {"T": lambda: given - w.V, "V": lambda: w.T - given, "L": lambda: given}[
        quantity
    ]()
    return [lagrange(d, lagrangian, k) - w.Q[k] for k in range(len(m.q))]


def lagrange(d: Derivation, lagrangian: sp.Expr, k: int) -> sp.Expr:
    """d/dt ∂L/∂q̇_k − ∂L/∂q_k, the total time derivative taken by the chain rule."""
    m = d.model
    p = partial(lagrangian, m.qd[k], m)
    rate = partial(p, t, m)
    for q, qd, qdd in zip(m.q, m.qd, m.qdd, strict=True):
        rate += partial(p, q, m) * qd + partial(p, qd, m) * qdd
    return rate - partial(lagrangian, m.q[k], m)


def linear_system(d: Derivation, rows: list[sp.Expr]) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """rows = A q̈ − b: A (row-major) and b; ExprError when q̈ is not in them linearly."""
    m = d.model
    a, b = [], []
    for row in rows:
        coefficients = [partial(row, qdd, m) for qdd in m.qdd]
        for c in coefficients:
            if any(partial(c, qdd, m) != 0 for qdd in m.qdd):
                raise ExprError(
                    "the accelerations appear non-linearly (q̈ squared, or inside a function): "
                    "such an equation does not give one motion to draw",
                    field="answer",
                )
        a += coefficients
        b.append(-row.xreplace(dict.fromkeys(m.qdd, sp.S.Zero)))
    return a, b


def compile_model(d: Derivation, rows: list[sp.Expr]) -> Any:
    """(t, q…, q̇…, params…) -> [A flat…, b…] as scalar math code (lambdify, cse)."""
    args, subs = _args(d)
    # d/dx of abs(x) or sign(x) brings DiracDelta(x), which no math module evaluates: it is 0
    # wherever it has a value, everywhere but the one point x = 0 a run never lands on exactly
    rows = [r.replace(sp.DiracDelta, lambda *_: sp.S.Zero) for r in rows]
    a, b = linear_system(d, rows)
    exprs = [_plain(e, subs) for e in (*a, *b)]
    allowed = set(args)
    stray = set().union(*(e.free_symbols for e in exprs)) - allowed
    if stray or any(e.has(sp.Derivative) for e in exprs):
        names = ", ".join(sorted(str(s) for s in stray)) or "a derivative"
        raise ExprError(f"uses {names}, which is not a variable of this scene", field="answer")
    return sp.lambdify(args, exprs, modules=_MATH, cse=True)


def _rhs(fn: Any, n: int, params: list[float]) -> Any:
    """The first-order right-hand side (q̇, q̈) of a compiled model at these parameters; raises
    _Stop where q̈ is singular or not finite."""

    def rhs(time_: float, y: np.ndarray) -> np.ndarray:
        state = y.tolist()
        try:
            values = fn(time_, *state, *params)
        except OverflowError:
            raise _Stop("its numbers overflow double precision") from None
        except ZeroDivisionError:
            raise _Stop("it divides by zero") from None
        except ValueError:
            raise _Stop(_DOMAIN) from None
        if any(isinstance(v, complex) for v in values):  # Python's (−1)**0.25 is complex
            raise _Stop(_DOMAIN)
        if n == 1:  # the common case, without numpy's linear algebra per call
            a, b = values
            if not (math.isfinite(a) and math.isfinite(b)) or abs(a) <= 1e-300:
                raise _Stop(_SINGULAR if math.isfinite(a) and math.isfinite(b) else _INFINITE)
            return np.array([state[1], b / a])
        a = np.array(values[: n * n], dtype=float).reshape(n, n)
        b = np.array(values[n * n :], dtype=float)
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            raise _Stop(_INFINITE)
        try:
            qdd = np.linalg.solve(a, b)
        except np.linalg.LinAlgError:
            raise _Stop(_SINGULAR) from None
        return np.concatenate([y[n:], qdd])

    return rhs


class _Watched:
    """One model as mechanics/stops.py sees a scene (its stop functions, n, rhs(params), and the
    derivation their fields are named in), so the answer's model is watched, and its stops
    located, by the very code that ends a /simulate run."""

    def __init__(self, d: Derivation, fn: Any, n: int, stops: list[StopFunction]) -> None:
        self.derivation, self.fn, self.n, self.stops = d, fn, n, stops

    def rhs(self, params: list[float]) -> Any:
        inner = _rhs(self.fn, self.n, params)

        def rhs(time_: float, y: np.ndarray) -> np.ndarray:
            try:
                return inner(time_, y)
            except _Stop as stop:  # stops.py gives up on a state where ArithmeticError is raised
                raise ArithmeticError(stop.why) from None

        return rhs


def scene_stops(d: Derivation) -> tuple[list[StopFunction], list[StopFunction]]:
    """The stops watched on the true run, and on the answer's: the same surfaces, less a
    string's tension (Newton's tension along the TRUE motion says nothing about where the
    answer's string would slacken)."""
    if not d.model.stops:
        return [], []
    c = compile_derivation(d)
    stops = c.stops
    return stops, [s for s, info in zip(stops, c.stop_specs, strict=True) if info.tension is None]


def integrate(
    fn: Any,
    n: int,
    y0: list[float],
    params: list[float],
    t_end: float,
    watched: _Watched | None = None,
    until: float | None = None,
) -> Run:
    """DOP853 step by step, sampled on a uniform grid; stops at a blow-up, a singular q̈, the
    step cap or the wall-time cap, keeping what it has. With ``watched``, it ends at the first
    of the scene's stops, its last sample the located state there (``stopped_at``); ``until``
    ends it sooner (where the true run ended), its last sample the state then. _Stop when it
    cannot start at all."""
    samples = min(MAX_SAMPLES, int(t_end * SAMPLES_PER_SECOND) + 1)
    grid = np.linspace(0.0, t_end, samples)
    rhs = _rhs(fn, n, params)
    out = np.empty((samples, 2 * n))
    out[0] = y0
    start = np.asarray(y0, dtype=float)
    rhs(0.0, start)  # a model singular at the start is refused by the caller
    run = Run(grid, out, 0.0)
    watch = None
    if watched is not None and watched.stops:
        at_start = stopped_at_start(watched, params, start, t_end)
        if at_start is not None:
            return _stopped(run, 1, at_start, 0.0, start)
        watch = StopWatch(watched, params, start)
    bound = t_end if until is None else min(until, t_end)
    if not bound > 0:
        return _cut(run, 1, 0.0, start)
    solver = DOP853(rhs, 0.0, start, bound, rtol=RTOL, atol=ATOL)
    k, steps, deadline = 1, 0, time.monotonic() + RUN_SECONDS
    while solver.status == "running":
        t_old = solver.t
        try:
            solver.step()
        except _Stop as stop:
            run.blew_up_at, run.why = float(solver.t), stop.why
            break
        if solver.status == "failed":
            run.blew_up_at, run.why = float(solver.t), "its step size fell to nothing"
            break
        if not np.all(np.isfinite(solver.y)) or np.max(np.abs(solver.y)) > BLOW_UP:
            run.blew_up_at, run.why = float(solver.t), f"|q| or |q̇| passed {BLOW_UP:g}"
        dense = solver.dense_output()
        if run.blew_up_at is None and watch is not None and watch(solver.t, solver.y):
            stop, t_stop, y_stop = _located(watch, watched, params, dense, t_old)
            while k < samples and grid[k] < t_stop and grid[k] <= solver.t:
                out[k] = dense(grid[k])
                k += 1
            return _stopped(run, k, stop, t_stop, y_stop)
        while k < samples and grid[k] <= solver.t:
            out[k] = dense(grid[k])
            k += 1
        run.reached = float(solver.t)
        if run.blew_up_at is not None:
            break
        steps += 1
        if steps >= MAX_STEPS or time.monotonic() > deadline:
            run.why = (
                f"it needs more than {MAX_STEPS} steps or {RUN_SECONDS:g} s (the motion is "
                "very fast, stiff or blowing up)"
            )
            break
    finite = np.all(np.isfinite(out[:k]), axis=1)
    k = int(np.argmin(finite)) if not finite.all() else k
    if solver.status == "finished" and bound < t_end and finite.all():
        return _cut(run, k, bound, solver.y)
    run.t, run.y = grid[:k], out[:k]
    return run


def _located(
    watch: StopWatch, watched: _Watched, params: list[float], dense: Any, t_old: float
) -> tuple[StopFunction, float, np.ndarray]:
    """Where the stop the watch saw is reached: a crossing within the last step is the root of
    the stop's value along that step's dense output (as scipy's event location finds it); a
    creep, a bounce or a value turning undefined go to the watch's own secant (mechanics/stops.py).
    """
    i, t0, _, t1, _, how = watch.hit
    stop, n = watched.stops[i], watched.n

    def value(s: float) -> float:
        y = dense(s)
        with np.errstate(all="ignore"):
            return float(np.asarray(stop.value(s, *y[:n], *y[n:], *params)[0]))

    if how == "crossed" and t0 == t_old:
        before, after = value(t0), value(t1)
        if math.isfinite(before) and math.isfinite(after) and before * after <= 0 < before**2:
            t_stop = t1 if after == 0 else brentq(value, t0, t1, xtol=1e-13, rtol=1e-13)
            return stop, float(t_stop), dense(t_stop)
    return watch.secant(params)


def _cut(run: Run, k: int, t: float, state: np.ndarray) -> Run:
    """The run's first k samples before t, then the state at t (a run's end off the grid)."""
    k = int(np.searchsorted(run.t[:k], t, "left"))
    return Run(
        np.append(run.t[:k], t),
        np.vstack([run.y[:k], state]),
        run.reached if run.reached > t else t,
        run.blew_up_at,
        run.why,
        run.stopped_at,
    )


def _stopped(run: Run, k: int, stop: StopFunction, t: float, state: np.ndarray) -> Run:
    """The run ended at a stop: cut there, the stop's message its reason."""
    out = _cut(run, k, t, state)
    out.reached, out.stopped_at, out.why = t, t, stop.message
    return out


def _state_at(fn: Any, n: int, params: list[float], run: Run, t: float) -> np.ndarray:
    """The run's state at time t within it, integrated from the last sample before (where the
    run is smooth: it has not reached a stop yet)."""
    j = int(np.searchsorted(run.t, t, "right")) - 1
    if run.t[j] == t:
        return run.y[j]
    sol = solve_ivp(
        _rhs(fn, n, params), (run.t[j], t), run.y[j], method="DOP853", rtol=RTOL, atol=ATOL
    )
    return sol.y[:, -1]


def initial_state(
    d: Derivation, parameters: dict[str, float], initial: dict[str, float]
) -> tuple[list[float], list[float]]:
    """The scene's parameters and initial state with the request's overrides (checked names)."""
    spec = d.model.spec
    errors = []
    for where, given, known in (
        ("parameters", parameters, set(spec.parameters)),
        ("initial", initial, set(spec.coordinates) | {f"{q}_dot" for q in spec.coordinates}),
    ):
        for name, value in given.items():
            if name not in known:
                errors.append({"field": f"{where}.{name}", "message": f"unknown name '{name}'"})
            elif not math.isfinite(value):
                errors.append({"field": f"{where}.{name}", "message": "must be a finite number"})
            elif where == "parameters" and value < 0 and d.model.params[name].is_nonnegative:
                # as /simulate refuses it: the derivation took the parameter as a magnitude
                errors.append(
                    {
                        "field": f"{where}.{name}",
                        "message": f"must be ≥ 0 (the scene takes {name} as a magnitude)",
                    }
                )
            elif where == "initial" and abs(value) > BLOW_UP:
                # a start past the blow-up line would be reported as a blow-up at once
                errors.append(
                    {
                        "field": f"{where}.{name}",
                        "message": f"must be at most {BLOW_UP:g} in size: a prediction stops "
                        "any run whose |q| or |q̇| passes that",
                    }
                )
    if errors:
        raise SpecError(errors)
    values = {**spec.parameters, **parameters}
    errors += physical_limit_errors(d.model, values)  # as /simulate: k − 3 < 0 at k = 1
    state = {**spec.initial, **initial}
    for q in spec.positive_coordinates:  # as /simulate: the derivation took q > 0 (r = √r²)
        if state.get(q, 0.0) <= 0:
            errors.append(
                {"field": f"initial.{q}", "message": f"must be > 0 ({q} is declared positive)"}
            )
    if errors:
        raise SpecError(errors)
    y0 = [state.get(q, 0.0) for q in spec.coordinates]
    y0 += [state.get(f"{q}_dot", 0.0) for q in spec.coordinates]
    return [values[k] for k in spec.parameters], y0


def cannot_start(
    d: Derivation,
    fn: Any,
    parameters: dict[str, float],
    initial: dict[str, float],
    why: str,
) -> list[dict[str, str]]:
    """Why the DERIVED equations cannot start, naming the request's value that stops them.

    The overrides are tried one at a time, each put back to the scene's own value: an override
    without which the equations start is to blame (l = 0 leaves the pendulum without inertia:
    ``parameters.l``). Failing that, all parameter overrides together, then the initial state's
    (a pole of the coordinates, like φ at θ = 0); the scene's own start last (``initial``).
    """
    spec, n = d.model.spec, len(d.model.q)

    def starts(params: dict[str, float], state: dict[str, float]) -> bool:
        values = {**spec.parameters, **params}
        start = {**spec.initial, **state}
        y0 = [start.get(q, 0.0) for q in spec.coordinates]
        y0 += [start.get(f"{q}_dot", 0.0) for q in spec.coordinates]
        try:
            _rhs(fn, n, [values[k] for k in spec.parameters])(0.0, np.asarray(y0, dtype=float))
        except _Stop:
            return False
        return True

    hints = {
        "parameters": "; a mass, length or inertia of 0 leaves a coordinate without inertia",
        "initial": "; the coordinates may be singular there (like φ at θ = 0 of spherical "
        "coordinates): start elsewhere",
    }

    def blame(where: str, given: dict[str, float]) -> list[dict[str, str]]:
        hint = hints[where] if why == _SINGULAR else ""
        return [
            {
                "field": f"{where}.{name}",
                "message": f"with {name} = {value:g} the scene's motion cannot start: {why}{hint}",
            }
            for name, value in given.items()
        ]

    for name in parameters:
        if starts({k: v for k, v in parameters.items() if k != name}, initial):
            return blame("parameters", {name: parameters[name]})
    if parameters and starts({}, initial):
        return blame("parameters", parameters)
    for name in initial:
        if starts(parameters, {k: v for k, v in initial.items() if k != name}):
            return blame("initial", {name: initial[name]})
    if initial and starts(parameters, {}):
        return blame("initial", initial)
    return [{"field": "initial", "message": f"the scene's motion cannot start here: {why}"}]


class _Drawing:
    """The true E = T + V, positions and frame axes as numpy functions of a trajectory."""

    def __init__(self, d: Derivation) -> None:
        m, w = d.model, d.work
        args, subs = _args(d)

        def vector(exprs: list) -> Any:
            return sp.lambdify(args, [_plain(e, subs) for e in exprs], modules=_NUMPY, cse=True)

        axes = (m.N.x, m.N.y, m.N.z)
        self.n = len(m.q)
        self.energy = vector([w.T, w.V])
        self.places = {name: vector([r.dot(u) for u in axes]) for name, r in m.positions.items()}
        self.frames = {
            name: vector([getattr(f.frame, a).dot(u) for a in "xyz" for u in axes])
            for name, f in m.frames.items()
        }

    def at(self, fn: Any, run: Run, params: list[float]) -> list[np.ndarray]:
        n, times = self.n, run.t
        with np.errstate(all="ignore"):
            out = fn(times, *run.y[:, :n].T, *run.y[:, n:].T, *(np.float64(p) for p in params))
        return [np.broadcast_to(np.asarray(v, dtype=float), times.shape) for v in out]

    def total(self, run: Run, params: list[float]) -> np.ndarray:
        """The true E = T + V along a run."""
        kinetic, potential = self.at(self.energy, run, params)
        return kinetic + potential

    def json(self, run: Run, params: list[float], names: list[str]) -> dict[str, Any]:
        n = self.n
        places = {k: self.at(f, run, params) for k, f in self.places.items()}
        frames = {k: np.stack(self.at(f, run, params), axis=1) for k, f in self.frames.items()}
        return {
            "t": _floats(run.t),
            "q": {q: _floats(run.y[:, i]) for i, q in enumerate(names)},
            "q_dot": {q: _floats(run.y[:, n + i]) for i, q in enumerate(names)},
            "energy": _floats(self.total(run, params)),
            "positions": {
                k: dict(zip("xyz", map(_floats, v), strict=True)) for k, v in places.items()
            },
            "frames": {k: [_floats(row) for row in v] for k, v in frames.items()},
            "reached": run.reached,
            "blew_up_at": run.blew_up_at,
            "stopped_because": run.why or None,
        }


def _floats(values: np.ndarray) -> list[float | None]:
    """JSON numbers (9 significant digits: enough to check the run against another); None where
    not finite."""
    return [float(f"{v:.9g}") if math.isfinite(v) else None for v in np.asarray(values).tolist()]


def parting(
    drawing: _Drawing, true: Run, student: Run, params: list[float]
) -> tuple[float | None, str]:
    """When the student's motion is first visibly apart from the true one, and the rule used."""
    k = min(len(true.t), len(student.t))
    cut_true = Run(true.t[:k], true.y[:k], true.reached)
    cut_student = Run(student.t[:k], student.y[:k], student.reached)
    tracks = {name: np.stack(drawing.at(fn, true, params)) for name, fn in drawing.places.items()}
    moving = [name for name, xyz in tracks.items() if np.ptp(xyz, axis=1).max() > 0]
    if moving:
        every = np.concatenate(list(tracks.values()), axis=1)
        size = float(np.linalg.norm(every.max(axis=1) - every.min(axis=1))) or 1.0
        gap = np.zeros(k)
        for name in moving:
            a = np.stack(drawing.at(drawing.places[name], cut_true, params))
            b = np.stack(drawing.at(drawing.places[name], cut_student, params))
            gap = np.maximum(gap, np.linalg.norm(a - b, axis=0))
        apart = np.nonzero(~(gap <= PART_FRACTION * size))[0]
        rule = (
            f"a body more than {PART_FRACTION:.0%} of the scene's size ({size:.3g}) "
            "from where it truly is"
        )
    else:
        n = drawing.n
        gap = np.max(np.abs(cut_true.y[:, :n] - cut_student.y[:, :n]), axis=1)
        apart = np.nonzero(~(gap <= PART_COORDINATE))[0]
        rule = f"a coordinate more than {PART_COORDINATE} (rad or m) from its true value"
    if len(apart):
        return float(true.t[apart[0]]), rule
    if student.blew_up_at is not None:
        return student.blew_up_at, rule
    return None, rule


def predict(
    d: Derivation,
    quantity: str,
    answer: str,
    coordinate: str | None = None,
    *,
    parameters: dict[str, float] | None = None,
    initial: dict[str, float] | None = None,
    t_end: float = T_END,
) -> dict[str, Any]:
    """Check the answer, then integrate its model beside the true one (see the module docstring).

    Raises SpecError (bad quantity, coordinate, overrides) or ExprError (unparseable answer, or
    one that gives no motion)."""
    if quantity not in PREDICTED:
        raise SpecError(
            [{"field": "quantity", "message": f"a prediction needs one of {', '.join(PREDICTED)}"}]
        )
    if not math.isfinite(t_end):
        raise SpecError([{"field": "t_end", "message": "must be a finite number"}])
    if not (0 < t_end <= MAX_T_END):
        raise SpecError([{"field": "t_end", "message": f"must be in (0, {MAX_T_END:g}] seconds"}])
    verdict = check(d, quantity, answer, coordinate)
    m = d.model
    j = m.coordinate_names.index(coordinate) if quantity in ("Q", "eom", "accel") else None
    given, _ = read_answer(d, quantity, answer, j)
    params, y0 = initial_state(d, parameters or {}, initial or {})
    n = len(m.q)
    true_rows = [expected_quantity(d, "eom", k) for k in range(n)]
    if quantity == "eom" and not any(given.has(a) for a in m.qdd):
        raise ExprError(
            f"your equation has no acceleration (${to_latex(m.qdd[j])}$ does not appear): it "
            "gives no motion to integrate",
            field="answer",
        )
    if quantity in ("T", "V", "L") and any(given.has(a) for a in m.qdd):
        raise ExprError(
            f"a {quantity} with accelerations in it gives equations of higher order than "
            "Lagrange's: there is no motion from q and q̇ alone to draw",
            field="answer",
        )
    student_fn = compile_model(d, equations(d, quantity, given, j))
    true_fn = compile_model(d, true_rows)
    true_stops, student_stops = scene_stops(d)
    true_model = _Watched(d, true_fn, n, true_stops)
    try:  # a start without inertia is named first: the stops' tensions are 0/0 there too
        _rhs(true_fn, n, params)(0.0, np.asarray(y0, dtype=float))
        if true_stops:  # as /simulate: a start past a stop is refused, naming the initial state
            refuse_passed_stops(true_model, params, np.asarray(y0, dtype=float))
        true = integrate(true_fn, n, y0, params, t_end, true_model)
    except _Stop as stop:
        raise SpecError(
            cannot_start(d, true_fn, parameters or {}, initial or {}, stop.why)
        ) from None
    try:  # not past the true run's stop: there is nothing to compare it with
        student = integrate(
            student_fn,
            n,
            y0,
            params,
            t_end,
            _Watched(d, student_fn, n, student_stops),
            until=true.stopped_at,
        )
    except _Stop as stop:
        raise ExprError(
            f"your answer gives no motion from the initial state: {stop.why}", field="answer"
        ) from None
    if student.blew_up_at is not None and student.reached == 0:
        raise ExprError(f"your answer's motion blows up at once: {student.why}", field="answer")
    if _ends_first(student, true.t[-1]):
        # the answer's motion ended first: the true one is shown and compared up to then only
        state = _state_at(true_fn, n, params, true, student.stopped_at)
        true = _cut(true, len(true.t), student.stopped_at, state)
    drawing = _Drawing(d)
    parted_at, rule = parting(drawing, true, student, params)
    kinetic, potential = drawing.at(drawing.energy, true, params)
    energy = energy_change(
        student.t, kinetic + potential, drawing.total(student, params), float(np.max(kinetic))
    )
    blamed = next((f for f in verdict.feedback if not f.startswith(("Read as", "Correct"))), None)
    return {
        "correct": verdict.correct,
        "feedback": verdict.feedback,
        "answer_latex": verdict.answer_latex,
        "true": drawing.json(true, params, m.coordinate_names),
        "student": drawing.json(student, params, m.coordinate_names),
        "parted_at": parted_at,
        "parting_rule": rule,
        **energy,
        "blamed": blamed,
        "summary": _summary(
            parted_at, student, energy, blamed, true, t_end, energy_unit=_energy_unit(d)
        ),
    }


def energy_change(
    times: np.ndarray, e_true: np.ndarray, e_student: np.ndarray, kinetic_max: float
) -> dict[str, Any]:
    """How much energy (the TRUE E = T + V) the student's run gains over the true run's, from
    the start to the last time it reached, as a fraction of the motion's energy: the largest
    kinetic energy of the true run (independent of V's datum), else |E(0)|, else 1."""
    k = min(len(e_true), len(e_student))
    drift = (e_student[:k] - e_student[0]) - (e_true[:k] - e_true[0])
    finite = np.isfinite(drift)
    last = k - 1 if finite.all() else max(0, int(np.argmin(finite)) - 1)
    scale = kinetic_max if kinetic_max > 0 else abs(float(e_true[0])) or 1.0
    return {
        "energy_change": float(drift[last]) / scale,
        "energy_change_max": float(np.max(np.abs(drift[: last + 1]))) / scale,
        "energy_scale": scale,
        "energy_until": float(times[last]),
    }


def _pct(x: float) -> str:
    """A share as a percentage that never reads 0 % for a share the sentence is about (0.4 %
    printed as '0%' next to 'up to 41 %' read as a contradiction, student play-test)."""
    return f"{x:.0%}" if x >= 0.1 else f"{100 * x:.2g}%"


def _summary(
    parted_at: float | None,
    student: Run,
    energy: dict[str, Any],
    blamed: str | None,
    true: Run | None = None,
    t_end: float | None = None,
    energy_unit: str = "",
) -> str:
    """One sentence a student reads first (math as $…$). When a run stopped before t_end
    without blowing up (a stop of the scene, too many steps), the comparison covers only the
    time both reached, and the sentence says so: "the same motion" over 0.45 s is not over 5 s."""
    parts = []
    if student.blew_up_at is not None:
        parts.append(
            f"your answer's motion blows up at t = {student.blew_up_at:.3g} s ({student.why})"
        )
    if parted_at is not None:
        parts.append(f"it parts visibly from the true motion at t = {_seconds(parted_at)} s")
    change, most = energy["energy_change"], energy["energy_change_max"]
    # the yardstick as a number the student can place: its unit, and the time it is taken over
    # when the comparison stops short of the run (a stop, or the answer's own run ending)
    scale = f"{energy['energy_scale']:.3g}{' ' + energy_unit if energy_unit else ''}"
    over = ""
    if true is not None and t_end is not None and len(true.t) and true.t[-1] < t_end * (1 - 1e-9):
        over = f" up to t = {_seconds(float(true.t[-1]))} s"
    if abs(change) >= 1e-3:
        verb = "creates" if change > 0 else "destroys"
        parts.append(
            f"measured with the true energy, your model {verb} energy: {_pct(abs(change))} of the "
            f"true motion's largest kinetic energy{over} ({scale}) "
            f"in {_seconds(energy['energy_until'])} s"
            + (f" (up to {_pct(most)} along the way)" if most > 1.5 * abs(change) else "")
        )
    elif most >= 1e-3:
        parts.append(
            f"measured with the true energy, your model's energy swings by up to {_pct(most)} "
            f"of the true motion's largest kinetic energy{over} ({scale})"
        )
    window = _ends(true, student) if true is not None else ""
    if not window and true is not None and t_end is not None and student.blew_up_at is None:
        cut = [(r.reached, whose, r.why) for r, whose in ((true, "the true"), (student, "your"))]
        reached, whose, why = min(cut, key=lambda c: c[0])
        if reached < t_end * (1 - 1e-9):
            window = (
                f" Compared over the first {reached:.2f} s only, where {whose} motion's run "
                f"stopped: {why or 'it was cut short'}."
            )
    if not parts:
        return f"Your answer predicts the same motion as the derivation.{window}"
    text = "; ".join(parts)
    text = text[0].upper() + text[1:]
    cause = f" The cause: {blamed[0].lower() + blamed[1:]}" if blamed else ""
    return f"{text}.{window}{cause}"


def _energy_unit(d: Derivation) -> str:
    """'J' when the scene's units make T an energy in SI (kg·m²/s²), else "": a scene without
    units has numbers only, and one in other units is not guessed at."""
    dims = scene_dimensions(d.model)
    if dims and units.dimension(sp.expand(d.work.T), dims) == (1, 2, -2):
        return "J"
    return ""


def _seconds(t: float) -> str:
    """A time as the sentence prints it: 2 decimals, or 2 digits under 0.01 s (a run ended by a
    stop after 3e-5 s read 'ends at t = 0.00 s … before the true one, which ends at 0.00 s')."""
    return f"{t:.2f}" if t == 0 or t >= 0.01 else f"{t:.2g}"


def _ends_first(student: Run, end: float | None) -> bool:
    """Did the answer's motion end at a stop before `end` (the true run's), by more than the
    round-off of locating the same stop on the same motion twice?"""
    if student.stopped_at is None:
        return False
    return end is None or student.stopped_at < end - 1e-9 * max(1.0, end)


def _ends(true: Run, student: Run) -> str:
    """When and why a motion ended at one of the scene's stops, and so where the comparison
    ends ("" when neither did)."""
    if _ends_first(student, true.stopped_at):
        text = f" Your answer's motion ends at t = {_seconds(student.stopped_at)} s ({student.why})"
        if true.stopped_at is not None:
            at = _seconds(true.stopped_at)
            same = true.why == student.why  # the same stop: its message once
            text += ", before the true one, which " + (
                f"gets there at t = {at} s" if same else f"ends at t = {at} s ({true.why})"
            )
        return f"{text}: the motions are compared up to t = {_seconds(student.stopped_at)} s only."
    if true.stopped_at is None:
        return ""
    text = f" The true motion ends at t = {_seconds(true.stopped_at)} s ({true.why})"
    if student.stopped_at is not None:  # at the same moment, to round-off: the same stop
        text += ", and so does yours"
    if student.blew_up_at is not None:  # the comparison ended sooner, as the sentence says
        return f"{text}."
    return f"{text}: the motions are compared up to then only."
