"""The work–precision trade for one scene, on demand: cost against error, and each method's order.

Every method of the registry runs the same problem (the scene at the asked parameters and start,
from 0 to ``t_end``) at several steps or tolerances; each run reports what it cost (wall time,
RHS evaluations) and how wrong it was: the state at ``t_end`` against a tight reference
(DOP853 at rtol = atol = 1e-13) and the energy error along the run (as /simulate measures it).

From the points, each method's *measured* order is fitted by least squares on log–log axes:

- fixed-step methods: log(error) against log(h). A method of order p has a global error C·h^p,
  so the slope is p.
- adaptive methods: log(error) against log(RHS evaluations), and the order is minus the slope.
  The controller picks steps h whose *estimated* local error matches the tolerance, and that
  estimate is of the embedded lower-order method (DOP853 advances with order 8 but estimates
  with orders 5 and 3): error against tolerance has slope p/(q+1), not p. The evaluations count
  the steps N ∝ 1/h, and the global error is still C·h^p ∝ N^(−p): against work the slope is −p.

Only points in the asymptotic range enter a fit: a point whose error is at the reference's
floor (rounding, or the reference's own error) or so large that the method is not yet
converging (beyond stability, or no digit right) is shown but excluded, with the reason.

The long run sets symplectic Euler beside RK4 at the same step over up to 10³ periods: on a
conservative, autonomous motion with a constant mass matrix the first keeps its energy error
bounded (it conserves a modified energy exactly), the second's drifts one way. Anywhere else
(`why_not_symplectic`: a damper, friction or a drive doing work, L depending on t, M changing
with the coordinates) the result says why not in words. There is no long run past a stop (the
equations there describe a motion the system does not have) nor without a period (a motion that
never repeats has no "periods", and a bounded error needs a bounded motion): the answer says so.

A chaotic motion makes every error grow like e^(λt): past the predictability horizon even the
reference has no digit right, and the points measure the system, not the methods. A second
reference at a looser tolerance finds that horizon (mechanics/divergence.py, as /simulate's
sensitivity check does), and the answer warns and says so on the points it concerns.

Everything is bounded: one wall-time budget per request covers the comparisons and the long run
(whose length in periods is what fits in what is left); a run cut short says so and stays out
of fits.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from mechanics.divergence import compare_runs, worth_classifying
from mechanics.integrators import METHODS, Trajectory, integrate
from mechanics.native import NativeUnavailable
from mechanics.numeric import CompiledScene, compiled_scene, compiled_spec, evaluate
from mechanics.simulate import (
    MAX_BRANCH_FLIPS,
    SimulationRequest,
    _OtherBranch,
    check_request,
    why_not_symplectic,
)
from mechanics.spec import SpecError

MAX_METHODS = 6
MAX_SETTINGS = 8
MAX_T_END = 100.0
#: A shorter run compares nothing but round-off (t_end = 1e-300 ran at steps of 1e-302).
MIN_T_END = 1e-3
#: Fixed steps one run may take, and all fixed-step runs of one request together.
MAX_STEPS_PER_RUN = 200_000
MAX_STEPS_TOTAL = 1_000_000
#: Seconds for all the runs of one call (the reference, the comparisons and the long run), and
#: the share the comparisons get when a long run is asked for too. The route gives a request
#: 4.5 s (app/routes/precision.py); a script or a test may give more.
MAX_SECONDS = 12.0
COMPARISON_SHARE = 0.6
#: Seconds of a long run called on its own (`long_run`); within a request it gets what is left.
LONG_RUN_SECONDS = 8.0
LONG_RUN_PERIODS = 1000
#: A long run shorter than this says too little about drift against bounded error: it is cut
#: (and says so) rather than shortened further.
LONG_RUN_MIN_PERIODS = 100
LONG_RUN_STEPS_PER_PERIOD = 30
LONG_RUN_MAX_STEPS = 30_000
#: The reference: DOP853 at the tightest tolerance the validation allows anyone.
REF_TOL = 1e-13
#: The second reference that tells where the first stops being one (1000× looser, as /simulate's
#: sensitivity check re-runs).
CHECK_TOL = 1e-10
#: Samples along each run, for its energy error (and the reference's final state).
SAMPLES = 201
#: Errors below FLOOR × (1 + |state|) are at the reference's own accuracy; above CEILING × the
#: same scale the method is not converging yet. Neither kind of point enters a fit.
FLOOR = 1e-11
CEILING = 1e-2

DEFAULT_STEPS_PER_T_END = (100, 200, 400, 800, 1600, 3200)
DEFAULT_TOLERANCES = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)


@dataclass
class PrecisionRequest:
    """What to compare: fixed-step methods at ``steps`` (s), adaptive ones at ``tolerances``
    (rtol = atol); None picks defaults (steps t_end/100 … t_end/3200, tolerances 1e-4 … 1e-10)."""

    methods: list[str] = field(default_factory=lambda: ["euler", "rk4", "DOP853"])
    parameters: dict[str, float] = field(default_factory=dict)
    initial: dict[str, float] = field(default_factory=dict)
    t_end: float = 10.0
    steps: list[float] | None = None
    tolerances: list[float] | None = None
    long_run: bool = False


def check_precision_request(req: PrecisionRequest) -> None:
    """Bounds before any work, each error naming its field (the route's models check types)."""
    errors = []

    def bad(path: str, message: str) -> None:
        errors.append({"field": path, "message": message})

    if not req.methods:
        bad("methods", "pick at least one method")
    if len(req.methods) > MAX_METHODS:
        bad("methods", f"at most {MAX_METHODS} methods at once")
    if len(set(req.methods)) != len(req.methods):
        bad("methods", "each method at most once")
    for i, m in enumerate(req.methods):
        if m not in METHODS:
            bad(f"methods[{i}]", f"unknown method; one of {', '.join(METHODS)}")
    if not (math.isfinite(req.t_end) and MIN_T_END <= req.t_end <= MAX_T_END):
        bad("t_end", f"must be ≥ {MIN_T_END:g} s and ≤ {MAX_T_END:g} s")
    for name, values in (("steps", req.steps), ("tolerances", req.tolerances)):
        if values is None:
            continue
        if not 1 <= len(values) <= MAX_SETTINGS:
            bad(name, f"give 1 to {MAX_SETTINGS} values")
        for i, v in enumerate(values):
            if name == "steps" and not (math.isfinite(v) and v > 0):
                bad(f"steps[{i}]", "must be a finite step > 0")
            elif name == "steps" and math.isfinite(req.t_end) and req.t_end / v > MAX_STEPS_PER_RUN:
                bad(f"steps[{i}]", f"t_end / step exceeds {MAX_STEPS_PER_RUN} steps")
            elif name == "steps" and math.isfinite(req.t_end) and v > req.t_end * (1 + 1e-9):
                # it ran as one step of t_end, so two such steps were one point said twice
                bad(f"steps[{i}]", f"must be ≤ t_end = {req.t_end:g} s (it would not be taken)")
            elif name == "tolerances" and not (math.isfinite(v) and 1e-12 <= v <= 1e-2):
                bad(f"tolerances[{i}]", "must be in [1e-12, 0.01] (above the reference's 1e-13)")
    if errors:
        raise SpecError(errors)
    fixed = [m for m in req.methods if METHODS[m].kind == "fixed"]
    steps = settings_of(req)[0]
    total = len(fixed) * sum(math.ceil(req.t_end / h) for h in steps)
    if total > MAX_STEPS_TOTAL:
        bad("steps", f"the fixed-step runs together exceed {MAX_STEPS_TOTAL} steps")
        raise SpecError(errors)


def settings_of(req: PrecisionRequest) -> tuple[list[float], list[float]]:
    """The steps and the tolerances the runs use (the defaults where none were given)."""
    steps = req.steps or [req.t_end / k for k in DEFAULT_STEPS_PER_T_END]
    return sorted(steps, reverse=True), sorted(req.tolerances or DEFAULT_TOLERANCES, reverse=True)


def fitted_order(x: list[float], err: list[float]) -> float | None:
    """Least-squares slope of log(err) against log(x); None with fewer than 2 distinct x."""
    lx, ly = np.log(np.asarray(x, dtype=float)), np.log(np.asarray(err, dtype=float))
    if len(lx) < 2 or np.ptp(lx) == 0:
        return None
    slope = np.polyfit(lx, ly, 1)[0]
    return float(slope)


#: Coarse fixed-step points whose slope to the next differs from the next pair's by more than this
#: fraction are not yet in the asymptotic range (error = C·h^p + higher terms that still count).
PRE_ASYMPTOTIC = 0.05


def leave_out_pre_asymptotic(points: list[dict[str, Any]]) -> None:
    """Mark the coarsest points (``points`` by decreasing h) excluded while the slope from each to
    the next differs from the following pair's by more than 5 %: in the asymptotic range the
    local slopes settle at p, before it they creep towards p (RK4 on a 1 rad swing: 3.46, 3.75,
    3.88, 3.95 as h halves). Adaptive points are too ragged for this test and are not touched."""
    used = [p for p in points if p["excluded"] is None]

    def slope(a: dict[str, Any], b: dict[str, Any]) -> float:
        return math.log(a["error"] / b["error"]) / math.log(a["h"] / b["h"])

    while len(used) >= 3 and all(p["error"] > 0 for p in used[:3]):
        if used[0]["h"] == used[1]["h"] or used[1]["h"] == used[2]["h"]:
            return
        first, second = slope(used[0], used[1]), slope(used[1], used[2])
        if abs(first - second) <= PRE_ASYMPTOTIC * abs(second):
            return
        used[0]["excluded"] = (
            f"not yet asymptotic (local slope {first:.2f} to the next point, then {second:.2f})"
        )
        used.pop(0)


class _Clock:
    """One wall-time budget shared by a request's runs."""

    def __init__(self, seconds: float) -> None:
        self.deadline = time.perf_counter() + seconds

    def left(self) -> float:
        return max(0.0, self.deadline - time.perf_counter())


def _run(c: CompiledScene, params, y0, t_eval, method: str, clock: _Clock, **kw: Any) -> Trajectory:
    native = None
    if method == "dop853_c":
        try:
            native = c.native_rhs(params)
        except NativeUnavailable:
            native = None  # the C loop calls the Python right-hand side back
    return integrate(
        c.rhs(params),
        y0,
        t_eval,
        method=method,
        second_order=c.n,
        native=native,
        max_wall_time=max(clock.left(), 1e-3),
        max_steps=MAX_STEPS_PER_RUN + 1,
        **kw,
    )


def energy_error(c: CompiledScene, params: list[float], run: Trajectory) -> np.ndarray:
    """|E − E0| / max T along the run, as /simulate measures it: the energy where the scene
    conserves it, the Jacobi integral where that is conserved instead, else the balance
    E − E0 − W_NC − W_drive (every agent that does work on the right)."""
    n, t, y = c.n, run.t, run.y
    q, qd = y[:, :n].T, y[:, n : 2 * n].T
    T, V = evaluate(c.energy, t, q, qd, params)
    scale = max(float(np.max(np.abs(T))) if len(T) else 0.0, 1e-300)
    conserved = {x["name"] for x in c.derivation.work.conserved}
    if "energy" in conserved:
        value = T + V
    elif c.jacobi is not None:
        (value,) = evaluate(c.jacobi, t, q, qd, params)
    else:
        value = T + V - y[:, 2 * n]
        if c.drive is not None:
            (e_minus_h,) = evaluate(c.drive, t, q, qd, params)
            value = value - (e_minus_h - e_minus_h[0]) - (y[:, 2 * n + 1] if c.extras > 1 else 0)
    with np.errstate(invalid="ignore"):  # a run that blew up: NaN, reported as no error
        return np.abs(value - value[0]) / scale


def _grid(t_end: float, dt: float | None) -> tuple[np.ndarray, float | None]:
    """Sample times of a run, and the step a fixed-step method then takes: it lands on every
    sample with equal steps ≤ dt (mechanics/integrators.py), so a grid of at most SAMPLES
    intervals, none shorter than dt, leaves the step the asked one or a little below it."""
    if dt is None:
        return np.linspace(0.0, t_end, SAMPLES), None
    intervals = max(1, min(SAMPLES - 1, math.ceil(t_end / dt - 1e-9)))
    per = max(1, math.ceil(t_end / intervals / dt - 1e-9))  # a step past t_end: one step
    return np.linspace(0.0, t_end, intervals + 1), t_end / (intervals * per)


NOT_CONVERGING = "not converging yet (no digit right, or beyond stability)"


def _cut_point() -> dict[str, Any]:
    """A point the time budget left no room for, not even for its reference run."""
    return {
        "wall_time": 0.0,
        "rhs_evaluations": 0,
        "steps": 0,
        "error": None,
        "energy_error": None,
        "status": "stopped",
        "excluded": "stopped: the time budget ran out before this point's reference run",
    }


def _point(
    c: CompiledScene, params, run: Trajectory, cost: Trajectory, reference: np.ndarray, scale
) -> dict[str, Any]:
    """One point of the diagram: ``cost`` is the run that went straight to t_end (an adaptive
    method's sampled twin takes the same steps plus dense-output evaluations at the samples,
    which are not the method's work), ``run`` the sampled one its errors are read from."""
    ok = run.status == "ok" and cost.status == "ok"
    err = float(np.max(np.abs(run.y[:, : 2 * c.n] - reference))) if ok else math.nan
    energy = energy_error(c, params, run)
    excluded = None
    if not ok:
        excluded = f"stopped: {run.message or cost.message}"
    elif not math.isfinite(err):
        excluded = "the state is not finite"
    elif err <= FLOOR * scale:
        excluded = "at the reference's floor (rounding, not the method)"
    elif err >= CEILING * scale:
        excluded = NOT_CONVERGING
    return {
        "wall_time": cost.wall_time,
        "rhs_evaluations": cost.nfev,
        "steps": cost.nsteps,
        "error": err if math.isfinite(err) else None,
        "energy_error": float(np.max(energy)) if np.all(np.isfinite(energy)) else None,
        "status": "ok" if ok else "stopped",
        "excluded": excluded,
    }


def work_precision(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    req: PrecisionRequest,
    seconds: float = MAX_SECONDS,
) -> dict[str, Any]:
    """The diagram's points and each method's fitted order (see the module's docstring).

    A point's error is the largest |y − y_ref| over the samples and over q and q̇ (one final
    state can pass near the reference by chance: a phase error crossing zero)."""
    clock = _Clock(seconds)
    references: dict[int, np.ndarray] = {}

    def reference_on(t_eval: np.ndarray) -> np.ndarray | None:
        """The reference on these samples; None when the budget ran out before it (that point
        is cut, as a run would be: the request is not refused for what it did not reach)."""
        if len(t_eval) not in references:
            ref = _run(c, params, y0, t_eval, "dop853_c", clock, rtol=REF_TOL, atol=REF_TOL)
            if ref.status != "ok" and references and clock.left() == 0.0:
                return None
            if ref.status != "ok":
                raise SpecError(reference_failed(c, params, y0, req, ref, clock))
            references[len(t_eval)] = ref.y[:, : 2 * c.n]
        return references[len(t_eval)]

    start = time.perf_counter()
    reference = reference_on(np.linspace(0.0, req.t_end, SAMPLES))
    reference_seconds = time.perf_counter() - start
    scale = 1.0 + float(np.max(np.abs(reference)))
    steps, tolerances = settings_of(req)
    horizon = predictability(c, params, y0, req.t_end, reference, clock)
    not_symplectic = why_not_symplectic(c, params)
    methods = []
    for i, name in enumerate(req.methods):
        info = METHODS[name]
        fixed = info.kind == "fixed"
        # each method an equal share of what is left (what one leaves over goes to the next), so
        # a cut takes every method's finest settings rather than the last method's all
        share = _Clock(clock.left() / (len(req.methods) - i))
        points = []
        for setting in steps if fixed else tolerances:
            kw = {"dt": setting} if fixed else {"rtol": setting, "atol": setting}
            t_eval, h = _grid(req.t_end, setting if fixed else None)
            reference_here = reference_on(t_eval)
            if reference_here is None:
                points.append({"setting": setting, "h": h, **_cut_point()})
                continue
            run = _run(c, params, y0, t_eval, name, share, **kw)
            cost = run if fixed else _run(c, params, y0, t_eval[[0, -1]], name, share, **kw)
            point = _point(c, params, run, cost, reference_here, scale)
            if fixed and setting > req.t_end * (1 + 1e-9):
                point["excluded"] = (
                    f"the step is longer than the motion, which ends at t = {req.t_end:.3g} s: "
                    "it ran as one step of that length"
                )
            if horizon is not None and point["excluded"] == NOT_CONVERGING:
                point["excluded"] = (
                    f"past the predictability horizon (t ≈ {horizon.trusted_until:.3g} s): "
                    "the error measures the motion's sensitivity, not the method"
                )
            points.append({"setting": setting, "h": h, **point})
        if fixed:
            leave_out_pre_asymptotic(points)
        used = [p for p in points if p["excluded"] is None]
        x = [p["h"] if fixed else p["rhs_evaluations"] for p in used]
        slope = fitted_order(x, [p["error"] for p in used])
        methods.append(
            {
                "method": name,
                "label": info.label,
                "kind": info.kind,
                "order": info.order,
                "symplectic": bool(info.symplectic) and not_symplectic is None,
                "not_symplectic": not_symplectic if info.symplectic else None,
                "fitted_order": None if slope is None else (slope if fixed else -slope),
                "fitted_against": "step h" if fixed else "RHS evaluations",
                "points_in_fit": len(used),
                "points": points,
            }
        )
    return {
        "t_end": req.t_end,
        "reference": {"method": "DOP853", "rtol": REF_TOL, "wall_time": reference_seconds},
        "error_scale": scale,
        "methods": methods,
        "seconds": seconds - clock.left(),
        # the budget ran out, or cut a method's share of it
        "cut": clock.left() == 0.0
        or any("budget" in (p["excluded"] or "") for m in methods for p in m["points"]),
        "warnings": [horizon_warning(horizon, req.t_end)] if horizon is not None else [],
    }


def predictability(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    t_end: float,
    reference: np.ndarray,
    clock: _Clock,
) -> Any:
    """How the reference and a second one at CHECK_TOL part (mechanics/divergence.py), when they
    part by 1 % of the motion before t_end; None when they do not (the reference holds), or when
    the second one did not finish (no claim either way)."""
    t_eval = np.linspace(0.0, t_end, SAMPLES)
    other = _run(c, params, y0, t_eval, "dop853_c", clock, rtol=CHECK_TOL, atol=CHECK_TOL)
    if other.status != "ok" or not worth_classifying(c.n, reference, other.y):
        return None
    verdict = compare_runs(c, params, t_eval, reference, other.y, (REF_TOL, CHECK_TOL))
    return verdict if verdict.trusted_until is not None else None


def horizon_warning(verdict: Any, t_end: float) -> str:
    """The sentence on a comparison that runs past where its reference stops being one."""
    parted = verdict.trusted_until
    if verdict.kind == "exponential":
        # a 1000× tighter run buys ln(1000)/λ more: past that the 1e-13 reference is lost too
        lost = parted + math.log(CHECK_TOL / REF_TOL) / verdict.rate
        why = (
            f"The motion is chaotic here: two reference runs (DOP853 at {REF_TOL:g} and "
            f"{CHECK_TOL:g}) part like e^(λt) with λ ≈ {verdict.rate:.2g} /s and differ by 1 % "
            f"of the motion from t ≈ {parted:.3g} s; from about t ≈ {lost:.3g} s even the "
            f"{REF_TOL:g} reference has no digit right."
        )
    else:
        why = (
            f"Two reference runs (DOP853 at {REF_TOL:g} and {CHECK_TOL:g}) differ by 1 % of the "
            f"motion from t ≈ {parted:.3g} s: past there the reference is not to be trusted."
        )
    return (
        f"{why} The errors at t_end = {t_end:g} s measure the system's sensitivity past its "
        "predictability horizon, not the methods: a point with no digit right says nothing "
        f"about its method. For a work–precision diagram take t_end below about {parted:.3g} s."
    )


def period_window(t_end: float) -> float:
    """How long a motion is watched for a period (and for a stop after t_end): 4·t_end, and at
    least 20 s (a double pendulum asked for 1 s turns back twice only by about 3 s)."""
    return min(max(4 * t_end, 20.0), 4 * MAX_T_END)


def period_of(
    c: CompiledScene, params: list[float], y0: np.ndarray, t_end: float, seconds: float = 2.0
) -> float | None:
    """The motion's period from its first coordinate's turning points (q̇₁ changes sign from + to
    − once a period) over a reference run of `period_window`; None if it never turns twice."""
    t_eval = np.linspace(0.0, period_window(t_end), 4001)
    run = _run(c, params, y0, t_eval, "dop853_c", _Clock(seconds), rtol=1e-10, atol=1e-10)
    v = run.y[:, c.n]
    i = np.nonzero((v[:-1] > 0) & (v[1:] <= 0))[0]
    if len(i) < 2:
        return None
    t = run.t
    crossings = t[i] + (t[i + 1] - t[i]) * v[i] / (v[i] - v[i + 1])
    return float(np.mean(np.diff(crossings)))


#: Symplectic Euler's share of a long run's seconds: one evaluation a step against RK4's four.
SYMPLECTIC_SHARE = 0.3


def long_run(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    t_end: float,
    seconds: float = LONG_RUN_SECONDS,
    *,
    period: float | None = None,
    periods: int = LONG_RUN_PERIODS,
) -> dict[str, Any]:
    """Symplectic Euler against RK4 at one step h = period / 30 over ``periods`` periods (a
    multiple of 20, at most 1000): each run's energy error envelope, the largest |ΔE| in each of
    100 windows, and whether it was cut by ``seconds`` (symplectic Euler gets 30 % of them, RK4
    the rest). ``period`` None finds it (`period_of`); a motion without one is refused, since
    "periods" of it would be an invented time scale (`long_run_or_why` says so in words)."""
    if period is None:
        period = period_of(c, params, y0, t_end)
    if period is None:
        raise ValueError("no period found: the motion does not repeat within period_window(t_end)")
    h = period / LONG_RUN_STEPS_PER_PERIOD
    periods = max(20, min(periods, LONG_RUN_MAX_STEPS // LONG_RUN_STEPS_PER_PERIOD) // 20 * 20)
    windows = 100
    # two steps between samples: the steps land on the samples unchanged (h stays period / 30),
    # and 15 samples a period find each period's largest T and |ΔE| (one a period would alias)
    samples_per_window = periods * (LONG_RUN_STEPS_PER_PERIOD // 2) // windows
    t_eval = np.linspace(0.0, periods * period, windows * samples_per_window + 1)
    runs = {}
    clock = _Clock(seconds)
    for method, share in (("symplectic_euler", SYMPLECTIC_SHARE), ("rk4", 1.0)):
        run = _run(c, params, y0, t_eval, method, _Clock(clock.left() * share), dt=h)
        err = energy_error(c, params, run)
        reached = len(err) - 1
        env = [
            float(np.max(err[k * samples_per_window : (k + 1) * samples_per_window + 1]))
            for k in range(reached // samples_per_window)
        ]
        runs[method] = {
            "t": [float(t_eval[(k + 1) * samples_per_window]) for k in range(len(env))],
            "energy_error": env,
            "status": run.status,
            "message": run.message,
            "rhs_evaluations": run.nfev,
            "wall_time": run.wall_time,
        }
    not_symplectic = why_not_symplectic(c, params)
    return {
        # a bounded energy error is symplectic Euler's only on a conservative autonomous motion
        # with M constant
        "symplectic_here": not_symplectic is None,
        "not_symplectic": not_symplectic,
        "period": period,
        "period_from": "turning points of the first coordinate",
        "periods": periods,
        "h": h,
        "runs": runs,
    }


def periods_that_fit(
    c: CompiledScene, params: list[float], y0: np.ndarray, period: float, seconds: float
) -> int:
    """How many periods (a multiple of 20, LONG_RUN_MIN_PERIODS … LONG_RUN_PERIODS) the long run
    can take in ``seconds``, from the cost of 150 RK4 steps timed here: the request's budget
    decides the length, which the answer reports (``periods``), rather than cutting both runs."""
    h = period / LONG_RUN_STEPS_PER_PERIOD
    # the first run of a scene's right-hand side in a process costs ten times a later one (a
    # first 150 steps took 67 ms, the next 6 ms): the faster of two probes is the one that counts
    per_step = math.inf
    for _ in range(2):
        probe = _run(c, params, y0, np.array([0.0, 150 * h]), "rk4", _Clock(0.2), dt=h)
        per_step = min(per_step, probe.wall_time / max(probe.nsteps, 1))
    # RK4's step, symplectic Euler's (~40 % of it), the energy along both, and a margin for a
    # machine whose load changes between the probe and the runs
    per_period = LONG_RUN_STEPS_PER_PERIOD * per_step * 1.4 * 1.6
    fit = int(seconds / per_period) // 20 * 20 if per_period > 0 else LONG_RUN_PERIODS
    return max(LONG_RUN_MIN_PERIODS, min(LONG_RUN_PERIODS, fit))


def long_run_or_why(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    req: PrecisionRequest,
    stop: dict[str, Any] | None,
    seconds: float,
) -> tuple[dict[str, Any] | None, str | None]:
    """The long run, or why there is none, in the words the page shows: not past a stop (before
    t_end, or within the stretch watched for a period: a motion that repeats and has not met
    its stop there never will), and not of a motion with no period."""
    clock = _Clock(seconds)
    window = period_window(req.t_end)
    stop = stop or _model_ends(c, replace(req, t_end=window))
    if stop is not None:
        return None, (
            f"No long run: the motion ends at t = {stop['t']:.3g} s ({stop['message']}), and "
            "past that stop the equations describe a motion the system does not have."
        )
    period = period_of(c, params, y0, req.t_end, seconds=min(2.0, clock.left() / 4))
    if period is None:
        return None, (
            f"No long run: the motion does not repeat (its first coordinate does not turn back "
            f"twice within {window:.3g} s), so it has no periods to count, and symplectic "
            "Euler's bounded energy error is a property of bounded, repeating motion."
        )
    periods = periods_that_fit(c, params, y0, period, clock.left())
    return long_run(c, params, y0, req.t_end, clock.left(), period=period, periods=periods), None


def reference_failed(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    req: PrecisionRequest,
    ref: Trajectory,
    clock: _Clock,
) -> list[dict[str, str]]:
    """The 422 of a reference run that did not finish, on the value to blame. A run that breaks
    at once (g = 1e308: the motion leaves double precision in its first steps) is the values'
    fault, not t_end's: each override is put back to the scene's own value in turn over the
    first thousandth of t_end, and one without which the run gets through is named."""
    message = f"the reference run did not finish: {ref.message}"
    reached = ref.t_reached if math.isfinite(ref.t_reached) else (ref.t[-1] if len(ref.t) else 0)
    if reached > 1e-3 * req.t_end or not (req.parameters or req.initial):
        return [{"field": "t_end", "message": message}]
    spec, n = c.derivation.model.spec, c.n
    window = np.linspace(0.0, 1e-3 * req.t_end, 3)

    def through(p: list[float], y: np.ndarray) -> bool:
        return _run(c, p, y, window, "DOP853", clock, rtol=1e-6, atol=1e-6).status == "ok"

    blamed = []
    for name, value in req.parameters.items():
        p = list(params)
        p[c.parameters.index(name)] = spec.parameters[name]
        if through(p, y0):
            blamed.append(("parameters", name, value))
    for name, value in req.initial.items():
        y = np.array(y0, dtype=float)
        q = name.removesuffix("_dot")
        i = c.coordinates.index(q) + (n if name.endswith("_dot") else 0)
        y[i] = spec.initial.get(name, 0.0)
        if through(params, y):
            blamed.append(("initial", name, value))
    if not blamed:
        return [{"field": "t_end", "message": message}]
    return [
        {
            "field": f"{where}.{name}",
            "message": f"with {name} = {value:g} the motion leaves double precision at once "
            f"({message})",
        }
        for where, name, value in blamed
    ]


def precision_compiled(c: CompiledScene, req: PrecisionRequest, seconds: float) -> dict[str, Any]:
    """Every run of one request within ``seconds``: the comparisons first (COMPARISON_SHARE of
    them when a long run is asked for), the long run in what is left."""
    check_precision_request(req)
    clock = _Clock(seconds)
    # the parameters and the start checked as /simulate checks them (names, bounds, a state where
    # the equations hold); the method and output rate there are placeholders that pass
    sim = SimulationRequest(
        parameters=req.parameters, initial=req.initial, t_end=req.t_end, fps=1.0
    )
    params, y0 = check_request(c, sim)
    stop = _model_ends(c, req)
    if stop is not None:  # compare the motion the system has, not the equations' beyond it
        req = replace(req, t_end=stop["t"])
    share = COMPARISON_SHARE if req.long_run and stop is None else 1.0
    out = work_precision(c, params, y0, req, clock.left() * share)
    out["scene_parameters"] = dict(zip(c.parameters, params, strict=True))
    out["long_run"], out["long_run_declined"] = (
        long_run_or_why(c, params, y0, req, stop, clock.left()) if req.long_run else (None, None)
    )
    out["stopped"] = stop
    return out


def _model_ends(c: CompiledScene, req: PrecisionRequest) -> dict[str, Any] | None:
    """Where /simulate's run of this start ends at a declared stop (a mass at the pulley, the
    particle at the cone's vertex), if before t_end: {"t", "message"}. The runs compared here
    ignore stops, so past it they measured the errors of a motion the system does not have
    (the hostile play-test's cone particle at r ≈ −205 m)."""
    if not c.derivation.model.stops:
        return None
    from mechanics.simulate import simulate_compiled

    probe = SimulationRequest(
        parameters=req.parameters,
        initial=req.initial,
        t_end=req.t_end,
        fps=1000.0 / req.t_end,  # its last sample is t_end itself
        method="dop853_c",
        check_sensitivity=False,
    )
    stats = simulate_compiled(c, probe)["stats"]
    if stats["status"] != "stopped" or "stop" not in stats:
        return None
    return {"t": float(stats["stop"]["t"]), "message": stats["stop"]["message"]}


def precision(
    scene_id: str | None = None,
    scene: dict | None = None,
    request: PrecisionRequest | None = None,
    seconds: float = MAX_SECONDS,
) -> dict[str, Any]:
    """The work–precision answer for a built-in scene (by id) or a spec; SpecError names bad
    fields. A state across a spring's anchor runs on that side's derivation, as /simulate does."""
    req = request or PrecisionRequest()
    check_precision_request(req)
    branches: dict[int, int] = {}
    for _ in range(MAX_BRANCH_FLIPS):
        key = tuple(sorted(branches.items()))
        c = compiled_scene(scene_id, key) if scene_id is not None else compiled_spec(scene, key)
        try:
            return precision_compiled(c, req, seconds)
        except _OtherBranch as other:
            branches = {**c.derivation.model.branches, **other.flips}
    raise SpecError([{"field": "initial", "message": "no derivation matches this state"}])


def precision_job(key: str, req: PrecisionRequest, seconds: float) -> dict[str, Any]:
    """A posted spec's work–precision in a pool worker (``key``: its canonical JSON)."""
    import json

    return precision(scene=json.loads(key), request=req, seconds=seconds)
