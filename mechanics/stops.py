"""Where a model stops holding: the spec's `stops` and the implicit ones, found and located.

A run is watched for them after every step it takes in Python (`StopWatch`) and searched on its
samples after a compiled run (`first_stop`); the moment is then located by re-integrating the
step with scipy's event detection, or by the secant where a discontinuity makes the steps chatter
instead of crossing (friction sticking). A state already past a stop is refused before a run
(`refuse_passed_stops`), and one exactly at a stop whose model ends there ends it at t = 0
(`stopped_at_start`). See docs/model.md, "Stops".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from mechanics.integrators import _PHYSICAL, METHODS, Trajectory, integrate
from mechanics.numeric import CompiledScene, evaluate
from mechanics.spec import SpecError


def applies(stop: Any, t: float, y: np.ndarray, n: int, params: list[float]) -> bool:
    """Does the stop apply in this state (its `only_if` ≥ 0)? An undefined (NaN) guard counts as
    applying: a model whose condition cannot even be evaluated has stopped holding."""
    if stop.only_if is None:
        return True
    q, qd = y[:n].tolist(), y[n : 2 * n].tolist()
    with np.errstate(all="ignore"):
        return not float(np.asarray(stop.only_if(t, *q, *qd, *params)[0])) < 0


@dataclass
class StopEvent:
    name: str
    message: str
    t: float
    run: Trajectory  # the run cut at the stop, its last sample the located state
    kind: str = "declared"


class StopWatch:
    """Asked after every step of a Python-stepped run: has a stop been reached since the last
    step? It remembers where, for `first_stop` to locate the moment.

    A stop counts as reached when its value crosses 0 (falls to 0, or changes sign). A sign-change
    stop whose crossing is a discontinuity of the equations (Coulomb friction at rest) may never
    be crossed: an adaptive integrator creeps towards 0 in ever smaller steps (caught within
    `NEAR_ZERO`), a fixed-step one hops back from near 0 (caught as a bounce: |value| had a
    minimum within one step's change of 0). Both are placed where the secant of the last two
    values meets 0.
    """

    NEAR_ZERO = 1e-9  # relative to the largest |value| the stop has had in the run

    def __init__(self, c: CompiledScene, params: list[float], y0: np.ndarray) -> None:
        self.c, self.params = c, params
        state = (0.0, np.array(y0, dtype=float), self._values(0.0, np.asarray(y0)))
        self.last, self.before_last = state, None
        self.scale = [abs(v) if math.isfinite(v) else 0.0 for v in state[2]]
        #: (stop index, t before, y before, t after, y after, how: "crossed" | "secant")
        self.hit: tuple[int, float, np.ndarray, float, np.ndarray, str] | None = None

    def _values(self, t: float, y: np.ndarray) -> list[float]:
        n = self.c.n
        q, qd = y[:n].tolist(), y[n : 2 * n].tolist()
        with np.errstate(all="ignore"):
            return [float(np.asarray(st.value(t, *q, *qd, *self.params)[0])) for st in self.c.stops]

    def guard(self, stop: Any, t: float, y: np.ndarray) -> bool:
        return applies(stop, t, y, self.c.n, self.params)

    def __call__(self, t: float, y: np.ndarray) -> bool:
        values = self._values(t, y)
        t1, y1, v1 = self.last
        for i, stop in enumerate(self.c.stops):
            before, now = v1[i], values[i]
            if math.isfinite(now):
                self.scale[i] = max(self.scale[i], abs(now))
            if math.isnan(now) and not math.isnan(before):  # the condition became undefined
                self.hit = (i, t1, y1, t, np.array(y, dtype=float), "crossed")
                return True
            if stop.crossing == "falls":
                if before > 0 >= now and self.guard(stop, t, y):
                    self.hit = (i, t1, y1, t, np.array(y, dtype=float), "crossed")
                    return True
                # a domain's end is approached tangentially (θ ~ (t₀ − t)² for x = l√θ, whose M
                # is infinite there): the steps creep into it and may bounce back off it
                near = 0 < now <= self.NEAR_ZERO * self.scale[i]
                if stop.kind == "domain" and near and self.guard(stop, t, y):
                    self.hit = (i, t1, y1, t, np.array(y, dtype=float), "secant")
                    return True
                continue
            if np.sign(before) != np.sign(now) and before != 0 and self.guard(stop, t, y):
                self.hit = (i, t1, y1, t, np.array(y, dtype=float), "crossed")
                return True
            near = 0 < abs(now) <= self.NEAR_ZERO * self.scale[i]
            if near and self.guard(stop, t, y):
                self.hit = (i, t1, y1, t, np.array(y, dtype=float), "secant")
                return True
            if self.before_last is not None:
                t0, y0, v0 = self.before_last
                lowest = abs(v0[i]) > abs(before) < abs(now) and abs(before) <= abs(before - v0[i])
                if lowest and np.sign(v0[i]) == np.sign(before) and self.guard(stop, t1, y1):
                    self.hit = (i, t0, y0, t1, y1, "secant")
                    return True
        self.before_last, self.last = self.last, (t, np.array(y, dtype=float), values)
        return False

    def secant(self, params: list[float]) -> tuple[Any, float, np.ndarray]:
        """Where the line through the last two values meets 0, and the state there.

        The state comes from integrating to that moment from the side the motion arrives on
        (before a crossing; after a creep or a bounce, which never crossed), where the equations
        are smooth: stepping from a state past a discontinuity would carry its other side's
        acceleration back (a block reported sticking while still moving).
        """
        i, t0, y0, t1, y1, _ = self.hit
        v0, v1 = self._values(t0, y0)[i], self._values(t1, y1)[i]
        if math.isnan(v1):  # the condition became undefined: where, by bisection
            return self.c.stops[i], *_first_undefined(self.c, self.c.stops[i], params, t0, y0, t1)
        if not math.isfinite(v0 - v1):
            return self.c.stops[i], t1, np.array(y1, dtype=float)
        reach = 1.0  # steps past the last one the secant may reach
        if self.c.stops[i].kind == "domain" and v0 > 0 and v1 > 0:
            # a tangential approach, v ~ (t_end − t)²: √v is linear in t, and the steps shrink
            # as they creep in (RK45 was still 12 steps short), so it may reach further
            v0, v1, reach = math.sqrt(v0), math.sqrt(v1), 1000.0
        t_stop = t1 if v0 == v1 else t1 + v1 * (t1 - t0) / (v0 - v1)
        t_stop = min(max(t_stop, t0), t1 + reach * (t1 - t0))
        crossed = np.sign(v0) != np.sign(v1)
        start, state = (t0, y0) if crossed or t_stop < t1 else (t1, y1)
        return self.c.stops[i], t_stop, _advance(self.c, params, start, state, t_stop)


def _first_undefined(c: CompiledScene, stop: Any, params, t0: float, y0: np.ndarray, t1: float):
    """Where a stop's condition first becomes undefined (NaN) in (t0, t1]: bisection on states
    integrated from (t0, y0), where it was defined."""
    n, lo, hi = c.n, t0, t1
    y_hi = _advance(c, params, t0, y0, t1)
    for _ in range(60):
        if hi - lo <= 1e-12 * max(1.0, abs(hi)):
            break
        mid = (lo + hi) / 2
        y = _advance(c, params, t0, y0, mid)
        with np.errstate(all="ignore"):
            value = float(np.asarray(stop.value(mid, *y[:n], *y[n : 2 * n], *params)[0]))
        if math.isnan(value):
            hi, y_hi = mid, y
        else:
            lo = mid
    return float(hi), y_hi


def _advance(c: CompiledScene, params: list[float], t0: float, y0: np.ndarray, t1: float):
    """The state at t1 from (t0, y0) on a smooth stretch, tightly; y0 itself if that fails."""
    if t1 == t0:
        return np.array(y0, dtype=float)
    try:
        with np.errstate(all="ignore"):
            sol = solve_ivp(c.rhs(params), (t0, t1), y0, method="DOP853", rtol=1e-12, atol=1e-12)
    except _PHYSICAL:
        return np.array(y0, dtype=float)
    return sol.y[:, -1] if sol.success else np.array(y0, dtype=float)


def watch_for_stops(c: CompiledScene, params: list[float], y0: np.ndarray) -> StopWatch | None:
    return StopWatch(c, params, y0) if c.stops else None


def _stop_values(c, stop, t, y, params) -> tuple[np.ndarray, np.ndarray | None]:
    with np.errstate(all="ignore"):
        return _stop_values_of(c, stop, t, y, params)


def _stop_values_of(c, stop, t, y, params) -> tuple[np.ndarray, np.ndarray | None]:
    n = c.n
    (value,) = evaluate(stop.value, t, y[:, :n].T, y[:, n : 2 * n].T, params)
    guard = None
    if stop.only_if is not None:
        (guard,) = evaluate(stop.only_if, t, y[:, :n].T, y[:, n : 2 * n].T, params)
    return value, guard


def refuse_passed_stops(c: CompiledScene, params: list[float], y0: np.ndarray) -> None:
    """A run may not start where its model already does not hold (a slack string, a block
    beyond the pulley): that is a 422 naming the initial state, not a motion to show.

    Nor where a stop cannot be evaluated (`when` = sqrt(theta − 5) at θ = 0.5): a NaN never
    crosses 0, so such a stop was silently never checked; it is a 422 naming its field.
    """
    errors = []
    declared = len(c.derivation.model.spec.stops)
    for i, stop in enumerate(c.stops):
        value, _ = _stop_values(c, stop, np.array([0.0]), y0[None, :], params)
        if math.isnan(value[0]):
            spec = c.derivation.model.spec.stops[i] if i < declared else None
            errors.append(
                {
                    "field": "initial"
                    if spec is None
                    else f"stops[{i}].{'when' if spec.when is not None else 'tension'}",
                    "message": f"the stop {stop.name} is undefined (not a number) in the "
                    "initial state (a square root of a negative number, 0/0, ...), so the run "
                    "could never tell whether it is reached: give an expression defined where "
                    "the run starts",
                }
            )
            continue
        if stop.crossing != "falls":
            continue
        if value[0] < 0:
            errors.append(
                {
                    "field": "initial",
                    "message": f"the model does not hold in this initial state ({stop.name}: "
                    f"{stop.message})",
                }
            )
    if errors:
        raise SpecError(errors)


def stopped_at_start(
    c: CompiledScene, params: list[float], y0: np.ndarray, t_end: float = 1.0
) -> Any | None:
    """The stop that ends the run at t = 0, if any: one whose value is exactly 0 at the start and
    whose model ends there.

    A falling stop at 0 ends it when the motion heads into its forbidden side (a pendulum at
    θ = 0 swinging to θ < 0 with `when` = θ: it used to run a full swing on that side); one
    that heads into the allowed side, or stays at 0, starts normally. A sign-change stop
    (`crossing` = "any") at 0 ends it only when its `only_if` is given and holds, the stop's
    own statement that the model ends there (static friction holds a block at rest); without a
    guard the state merely starts on the surface (θ = 0 moving, a velocity 0 at release) and
    the run stops where the value next changes sign.
    """
    for stop in c.stops:
        value, guard = _stop_values(c, stop, np.array([0.0]), y0[None, :], params)
        if value[0] != 0 or (guard is not None and guard[0] < 0):
            continue
        if stop.crossing == "any" and stop.only_if is not None:
            return stop
        if stop.crossing == "falls" and _heading(c, stop, params, y0, t_end) < 0:
            return stop
    return None


def _heading(c: CompiledScene, stop: Any, params: list[float], y0: np.ndarray, t_end: float):
    """The sign a stop's value takes just after t = 0 (where it is 0): +1, −1, or 0 when it stays
    at 0 as far as a short look ahead can tell (an equilibrium on the surface)."""
    n = c.n
    horizon = min(t_end, 1.0)
    for h in (1e-6 * horizon, 1e-4 * horizon, 1e-2 * horizon):
        if not h > 0:
            break
        y = _advance(c, params, 0.0, y0, h)
        with np.errstate(all="ignore"):
            v = float(np.asarray(stop.value(h, *y[:n], *y[n : 2 * n], *params)[0]))
        if not math.isfinite(v):
            return -1  # undefined just past the start: it left the model at once
        if abs(v) > 1e-12:
            return 1 if v > 0 else -1
    return 0


def first_stop(
    c: CompiledScene, run: Any, params: list[float], req: Any, watch: StopWatch | None = None
) -> StopEvent | None:
    """The first declared (or implicit) stop the run reaches, located by re-integrating from the
    sample before it with scipy's event location (a root of the stop function on the step's
    dense output, to the run's tolerance). A run that ended early (a watched stop between two
    samples, a blow-up at a branch point) is searched one sample interval past its last sample.
    """
    if not c.stops or len(run.t) < 1:
        return None
    if watch is not None and watch.hit is not None:
        _, t_prev, y_prev, t_hit, _, how = watch.hit
        found = _locate(c, t_prev, y_prev, t_hit, params, req) if how == "crossed" else None
        stop, t_stop, y_stop = found or watch.secant(params)
        return _cut(run, len(run.t), stop, t_stop, y_stop)
    k, first = None, None
    if len(run.t) >= 2:
        for stop in c.stops:
            value, guard = _stop_values(c, stop, run.t, run.y, params)
            hit = _crossing(value, stop.crossing, guard)
            if hit is not None and (k is None or hit < k):
                k, first = hit, stop
    if k is not None:
        t0, y0, t1 = run.t[k - 1], run.y[k - 1], run.t[k]
    elif run.status != "ok":
        k = len(run.t)
        t0, y0 = run.t[-1], run.y[-1]
        t1 = min(t0 + 1.0 / req.fps, req.t_end) if req.t_end > t0 else t0
        if t1 <= t0:
            return None
    else:
        return None
    found = _locate(c, t0, y0, t1, params, req)
    if found is None and first is not None and first.kind == "anchor":
        # a spring's length |d| touches 0 and grows again (a body through its anchor in a
        # plane): no sign change for the event search, so step the interval again, watched
        found = _domain_end(c, params, run, t0, y0, t1, kind="anchor")
    if found is None and first is not None:  # not located: the condition became undefined
        found = first, *_first_undefined(c, first, params, t0, y0, t1)
    if found is None and run.status != "ok":  # a fixed step may land past a domain's end
        found = _domain_end(c, params, run, t0, y0, t1)
    if found is None:
        return None
    stop, t_stop, y_stop = found
    return _cut(run, k, stop, t_stop, y_stop)


def _domain_end(
    c: CompiledScene,
    params: list[float],
    run: Any,
    t0,
    y0: np.ndarray,
    t1: float,
    kind: str = "domain",
):
    """A domain's end in (t0, t1] that a run ending early there did not see: its steps (a fixed
    step of rk4) landed past it, where the right-hand side is NaN, and a tangential approach
    (x = l sin√θ touches θ = 0) changes no sign for the event search. Stepped again, tightly and
    watched, the steps creep into it as `StopWatch` expects. The same for a spring's length
    that touches 0 between two samples of a run that was not watched (the C loop's):
    ``kind="anchor"``."""
    if not any(stop.kind == kind for stop in c.stops) or not t1 > t0:
        return None
    watch = StopWatch(c, params, np.asarray(y0, dtype=float))
    watch.last = (t0, np.array(y0, dtype=float), watch._values(t0, np.asarray(y0)))
    for i, stop in enumerate(c.stops):  # "near 0" is relative to the whole run's values
        value, _ = _stop_values(c, stop, run.t, run.y, params)
        finite = np.abs(value[np.isfinite(value)])
        watch.scale[i] = max(watch.scale[i], float(finite.max()) if len(finite) else 0.0)
    try:
        with np.errstate(all="ignore"):
            integrate(
                c.rhs(params),
                np.asarray(y0, dtype=float),
                np.array([t0, t1]),
                method="DOP853",
                rtol=1e-10,
                atol=1e-12,
                second_order=c.n,
                max_wall_time=2.0,
                watch=watch,
            )
    except (ValueError, *_PHYSICAL):
        return None
    if watch.hit is None or c.stops[watch.hit[0]].kind != kind:
        return None
    return watch.secant(params)


def _cut(run: Any, k: int, stop: Any, t_stop: float, y_stop: np.ndarray) -> StopEvent:
    """The run's first k samples, then the located state at the stop."""
    k = int(np.searchsorted(run.t[:k], t_stop, "left"))
    cut = Trajectory(
        np.append(run.t[:k], t_stop),
        np.vstack([run.y[:k], y_stop]),
        "stopped",
        f"{stop.name} at t = {t_stop:.6g} s",
        run.nfev,
        run.nsteps,
        run.njev,
        run.wall_time,
        run.note,
    )
    return StopEvent(stop.name, stop.message, float(t_stop), cut, stop.kind)


def _crossing(value: np.ndarray, crossing: str, guard: np.ndarray | None) -> int | None:
    """The first sample index k ≥ 1 at which the condition has been reached since k − 1."""
    undefined = np.nonzero(np.isnan(value[1:]) & ~np.isnan(value[:-1]))[0] + 1
    if crossing == "falls":
        hits = np.nonzero((value[1:] <= 0) & (value[:-1] > 0))[0] + 1
        if value[0] == 0:
            hits = np.concatenate([np.nonzero(value[1:] < 0)[0][:1] + 1, hits])
    else:
        hits = np.nonzero(np.sign(value[1:]) != np.sign(value[:-1]))[0] + 1
        hits = hits[~np.isnan(value[hits]) & ~np.isnan(value[hits - 1])]
    for k in np.sort(np.concatenate([hits, undefined])).astype(int):
        applies = guard is None or not guard[k] < 0 or not guard[k - 1] < 0  # NaN: it applies
        if applies or k in undefined:
            return int(k)
    return None


#: Right-hand-side calls one location may spend (a chattering discontinuity would take forever).
_LOCATE_CALLS = 50_000


class _LocateBudget(Exception):
    pass


#: Event searches per located stop: a guarded stop whose guard fails is passed and searched on.
_MAX_EVENT_RESTARTS = 8


def _locate(c, t0, y0, t1, params, req) -> tuple[Any, float, np.ndarray] | None:
    """Integrate [t0, t1] with every stop as a terminal event; the first whose guard holds."""
    n = c.n
    method = req.method if req.method in ("RK45", "DOP853", "Radau", "BDF", "LSODA") else "DOP853"
    fixed = METHODS[req.method].kind == "fixed"
    rtol, atol = (1e-10, 1e-12) if fixed else (req.rtol, req.atol)

    def event(stop):
        def g(time: float, y: np.ndarray) -> float:
            q, qd = y[:n].tolist(), y[n : 2 * n].tolist()
            return float(np.asarray(stop.value(time, *q, *qd, *params)[0]))

        g.terminal = True
        g.direction = -1 if stop.crossing == "falls" else 0
        return g

    rhs, calls = c.rhs(params), [0]

    def budgeted(time: float, y: np.ndarray) -> np.ndarray:
        calls[0] += 1
        if calls[0] > _LOCATE_CALLS:
            raise _LocateBudget
        return rhs(time, y)

    def pending(time: float, y: np.ndarray) -> list[int]:
        """The stops still ahead: a falling stop already at or below 0 (its guard failed, or it
        is 0 for good) cannot fall again without rising first."""
        out = []
        for i, stop in enumerate(c.stops):
            g = event(stop)(time, y)
            if stop.crossing == "any" or not g <= 0:
                out.append(i)
        return out

    start, state = t0, np.asarray(y0, dtype=float)
    for _ in range(_MAX_EVENT_RESTARTS):
        ahead = pending(start, state)
        if not ahead:
            return None
        try:
            with np.errstate(all="ignore"):
                sol = solve_ivp(
                    budgeted,
                    (start, t1),
                    state,
                    method=method,
                    rtol=rtol,
                    atol=atol,
                    events=[event(c.stops[i]) for i in ahead],
                )
        except (_LocateBudget, ValueError, *_PHYSICAL):
            return None
        hits = [
            (te[0], i, ye[0])
            for i, te, ye in zip(ahead, sol.t_events, sol.y_events, strict=True)
            if len(te)
        ]
        if not hits:
            return None
        t_hit, i, y_hit = min(hits, key=lambda h: h[0])
        stop = c.stops[i]
        if applies(stop, t_hit, y_hit, n, params):
            return stop, float(t_hit), y_hit
        if t_hit >= t1:
            return None
        start, state = float(np.nextafter(t_hit, np.inf)), y_hit
    return None
