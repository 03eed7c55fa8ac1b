"""Runs an integrator on a compiled scene and says what the run cost and how accurate it was.

Every run reports its accuracy against something the integrator does not control: the energy
(or Jacobi integral) that the equations conserve, the balance E − E0 = W_NC when forces do work,
and the momenta of cyclic coordinates. Where a result cannot be trusted the run says so in
`warnings` rather than presenting it as exact: a stopped run, a large energy error, a mass matrix
that is nearly singular (a coordinate singularity), and results that change with the tolerance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp
from scipy.integrate import cumulative_simpson

from mechanics.divergence import compare_runs, worth_classifying
from mechanics.expr import to_plain
from mechanics.integrators import _PHYSICAL, METHODS, Trajectory, integrate
from mechanics.model import T as T_SYMBOL
from mechanics.model import limits_along_run, physical_limit_errors
from mechanics.numeric import (
    EXTREME_EXPONENT,
    CompiledScene,
    compiled_scene,
    compiled_spec,
    constraint_force_functions,
    evaluate,
    overflow_error,
    velocity_jump_functions,
)
from mechanics.scene_run import DEFAULT_METHOD, run_scene
from mechanics.spec import SpecError
from mechanics.steps.conserved import explicit_time, vanishes
from mechanics.stops import (
    StopEvent,
    first_stop,
    refuse_passed_stops,
    stopped_at_start,
)

MAX_T_END = 1000.0
#: The output rate is bounded by the samples it makes (t_end × fps + 1), not by a rate cap: 100
#: samples over 1 ms of a stiff spring (fps = 1e5) is a fair request.
MAX_SAMPLES = 20_001
MAX_WALL_TIME = 10.0
#: Derivations one request may ask for: its own and the variant with springs on the other side of
#: their anchors (all flipped at once; a second flip means the state moved, which it cannot).
MAX_BRANCH_FLIPS = 2
MAX_FIXED_STEPS = 2_000_000
#: Above this relative energy error the run carries a warning.
ENERGY_WARNING = 1e-3


@dataclass
class SimulationRequest:
    parameters: dict[str, float] = field(default_factory=dict)
    initial: dict[str, float] = field(default_factory=dict)
    t_end: float = 10.0
    fps: float = 60.0
    method: str = DEFAULT_METHOD
    rtol: float = 1e-9
    atol: float = 1e-9
    dt: float | None = None
    check_sensitivity: bool = True
    constraint_forces: bool = False


def check_request(c: CompiledScene, req: SimulationRequest) -> tuple[list[float], np.ndarray]:
    """Bounds and names, each error naming its field; returns parameter values and y0."""
    spec = c.derivation.model.spec
    errors = []
    for name, value in req.parameters.items():
        if name not in spec.parameters:
            errors.append({"field": f"parameters.{name}", "message": f"unknown parameter '{name}'"})
        elif not math.isfinite(value):
            errors.append({"field": f"parameters.{name}", "message": "must be a finite number"})
        elif name in c.nonnegative and value < 0:
            errors.append(
                {
                    "field": f"parameters.{name}",
                    "message": f"must be ≥ 0 (the scene takes {name} as a magnitude)",
                }
            )
    allowed = set(c.coordinates) | {f"{q}_dot" for q in c.coordinates}
    for name, value in req.initial.items():
        if name not in allowed:
            errors.append({"field": f"initial.{name}", "message": f"unknown coordinate '{name}'"})
        elif not math.isfinite(value):
            errors.append({"field": f"initial.{name}", "message": "must be a finite number"})
    checks = [
        (
            "t_end",
            math.isfinite(req.t_end) and 0 <= req.t_end <= MAX_T_END,
            f"must be between 0 and {MAX_T_END:g} s",
        ),
        ("fps", math.isfinite(req.fps) and req.fps > 0, "must be a finite number > 0"),
        ("method", req.method in METHODS, f"unknown method; one of {', '.join(METHODS)}"),
        ("rtol", math.isfinite(req.rtol) and 1e-14 <= req.rtol <= 1e-1, "must be in [1e-14, 0.1]"),
        ("atol", math.isfinite(req.atol) and 1e-16 <= req.atol <= 1, "must be in [1e-16, 1]"),
    ]
    if req.t_end * req.fps + 1 > MAX_SAMPLES:  # inf (an overflowing product) is refused too
        checks.append(("fps", False, f"t_end × fps + 1 gives more than {MAX_SAMPLES} samples"))
    if req.method in METHODS and METHODS[req.method].kind == "fixed":
        ok = req.dt is not None and math.isfinite(req.dt) and req.dt > 0
        checks.append(("dt", ok, "a fixed-step method needs a step dt > 0"))
        if ok and req.t_end / req.dt > MAX_FIXED_STEPS:
            checks.append(("dt", False, f"t_end / dt exceeds {MAX_FIXED_STEPS} steps"))
        elif ok and math.isfinite(req.t_end) and 0 < req.t_end < req.dt * (1 - 1e-9):
            checks.append(
                (
                    "dt",
                    False,
                    f"must be ≤ t_end = {req.t_end:g} s: a step of dt = {req.dt:g} s would "
                    "end past the run, so not one step of it fits",
                )
            )
    errors += [{"field": f, "message": m} for f, ok, m in checks if not ok]
    if errors:
        raise SpecError(errors)
    values = {**spec.parameters, **req.parameters}
    # at these values and this start (a limit in t or q at t = 0, q0), not the spec's
    errors += physical_limit_errors(c.derivation.model, values, req.initial)
    init = {**spec.initial, **req.initial}
    for q in spec.positive_coordinates:
        if init.get(q, 0.0) <= 0:
            errors.append(
                {"field": f"initial.{q}", "message": f"must be > 0 ({q} is declared positive)"}
            )
    if errors:
        raise SpecError(errors)
    y0 = [init.get(q, 0.0) for q in c.coordinates] + [
        init.get(f"{q}_dot", 0.0) for q in c.coordinates
    ]
    params = [values[k] for k in c.parameters]
    state = np.array([*y0, *[0.0] * c.extras])
    check_state(c, params, state, req)
    return params, state


def _at(fn: Any, t0: float, y0: np.ndarray, n: int, params: list[float]) -> list[float]:
    """An array function at one state."""
    t = np.array([t0])
    return [float(v[0]) for v in evaluate(fn, t, y0[:n, None], y0[n : 2 * n, None], params)]


def check_state(c: CompiledScene, params: list[float], y0: np.ndarray, req: Any) -> None:
    """The state a run starts from must lie where the derived equations hold: every branched
    spring on the side it was derived for and off its anchor, a mass matrix that can be
    inverted, and numbers a double can hold (declared stops: `stops.refuse_passed_stops`).

    A start at (or past) the end of a position's domain (x = l√θ at θ = 0) makes M infinite
    there, which read as "M overflows double precision: pick units"; it is refused as what it
    is, naming the coordinates whose value puts it there."""
    try:
        _check_state(c, params, y0, req)
    except SpecError:
        at_end = _at_domain_end(c, params, y0)
        if at_end is not None:
            raise SpecError([at_end]) from None
        raise


def _at_domain_end(c: CompiledScene, params: list[float], y0: np.ndarray) -> dict | None:
    """The 422 entry for a start at or past a position's domain end, else None."""
    m, n = c.derivation.model, c.n
    for stop, spec in zip(c.stops, c.stop_specs, strict=True):
        if stop.kind != "domain":
            continue
        with np.errstate(all="ignore"):
            value = float(np.asarray(stop.value(0.0, *y0[:n], *y0[n : 2 * n], *params)[0]))
        if value > 0:
            continue
        involved = [
            name for name, q in zip(m.coordinate_names, m.q, strict=True) if spec.when.has(q)
        ]
        where = ", ".join(
            f"{q} = {y0[j]:g}" for j, q in enumerate(m.coordinate_names) if q in involved
        )
        end = to_plain(spec.when)
        what = stop.message.split(" is undefined")[0]  # "the position of b"
        return {
            "field": ", ".join(f"initial.{q}" for q in involved) or "initial",
            "message": f"the run would start {'at' if value == 0 else 'past'} the end of the "
            f"domain of coordinates where {what} is defined ({where}): it is undefined for "
            f"{end} < 0, and at {end} = 0 the equations of motion cannot be evaluated (the mass "
            f"matrix is infinite or singular there); start where {end} > 0",
        }
    return None


def _check_state(c: CompiledScene, params: list[float], y0: np.ndarray, req: Any) -> None:
    n, m = c.n, c.derivation.model
    errors = []
    names = ", ".join(f"initial.{q}" for q in c.coordinates if q in req.initial) or "initial"
    flips = {}
    for i, fn in c.branch_values.items():
        spring = m.springs[i]
        if _rest_length(c, spring, params) == 0:
            continue  # ½k p² is smooth through the anchor, the same on either side: no branch
        (p,) = _at(fn, 0.0, y0, n, params)
        # the scale of p: the coordinates it is made of (not an unrelated one's size)
        own = [abs(y0[j]) for j, q in enumerate(m.q) if spring.branch.has(q)]
        if not abs(p) > 1e-12 * max([1.0, *own]):
            errors.append(
                {
                    "field": names,
                    "message": f"the spring {spring.name} has zero length in this state (at its "
                    "anchor its direction is undefined): start it off the anchor",
                }
            )
        elif p < 0:
            flips[i] = -spring.sign
    if flips and not errors:
        raise _OtherBranch(flips)  # every spring on its other side at once: one re-derivation
    mass = np.array(_at(c.mass_matrix, 0.0, y0, n, params)).reshape(n, n)
    overflow = _overflow(c, params, y0, mass, moves=False)
    if overflow:
        raise SpecError([_too_large(c, params, req, overflow)])
    with np.errstate(all="ignore"):
        eig = np.linalg.eigvalsh((mass + mass.T) / 2)
    singular = not np.all(np.isfinite(eig)) or min(eig) <= 1e-14 * max(abs(e) for e in eig)
    if singular and req.t_end > 0:  # a zero-length run only places the bodies: nothing moves
        errors.append(_singular_mass(c, params, names))
    if errors:
        raise SpecError(errors)
    overflow = _overflow(c, params, y0, mass, moves=req.t_end > 0)
    if overflow == DIVISION_BY_ZERO:
        message = (
            "the equations divide by zero in this state (a damper or spring at zero length, "
            "where its direction is undefined, or a coordinate singularity): start elsewhere"
        )
        raise SpecError([{"field": names, "message": message}])
    if overflow:
        raise SpecError([_too_large(c, params, req, overflow)])


DIVISION_BY_ZERO = "division by zero"


def _rest_length(c: CompiledScene, spring: Any, params: list[float]) -> float | None:
    """A spring's rest length at these parameter values (None if it is not a number)."""
    symbols = c.derivation.model.params
    values = {symbols[k]: sp.Float(v) for k, v in zip(c.parameters, params, strict=True)}
    try:
        return float(spring.rest_length.xreplace(values))
    except (TypeError, ValueError):
        return None


def _overflow(
    c: CompiledScene, params: list[float], y0: np.ndarray, mass: np.ndarray, moves: bool
) -> str:
    """What is not a finite double at the initial state (M, T, V, and q̈ of a run that
    moves), or "" when all are. Asked before the singularity check without q̈ (a singular M
    makes q̈ infinite for another reason), then after it with q̈.

    A parameter like l = 1e155 is finite, but m·l² is not: such a run could only return inf and
    nan, so it is refused up front, naming what overflowed.
    """
    if not np.all(np.isfinite(mass)):
        return "the mass matrix M"
    T, V = _at(c.energy, 0.0, y0, c.n, params)
    if not math.isfinite(T + V):
        return "the energy T + V"
    if not moves:
        return ""
    try:
        with np.errstate(all="ignore"):
            accel = np.asarray(c.rhs(params)(0.0, np.asarray(y0, dtype=float)), dtype=float)
    except ZeroDivisionError:
        return DIVISION_BY_ZERO
    except _PHYSICAL:  # math.exp, a Python float's ** or / past the range of a double
        return "the accelerations q̈"
    return "" if np.all(np.isfinite(accel)) else "the accelerations q̈"


def _overflowed(
    c: CompiledScene, params: list[float], req: Any, run: Trajectory
) -> dict[str, str] | None:
    """Why a run that turned non-finite did, when a parameter or initial value is extreme
    (g = 1e308: q̈ = −g sin θ is finite at the start, and the first step overflows): the 422
    entry naming them, as at the start. None when every value is of ordinary size: then inf is
    the motion's own (a blow-up in finite time), and the run's message says when."""
    text = run.message.lower()
    if "non-finite" not in text and "overflow" not in text:
        return None
    values = {f"parameters.{k}": v for k, v in zip(c.parameters, params, strict=True)}
    values |= {f"initial.{k}": v for k, v in req.initial.items()}
    if not any(v != 0 and abs(math.log10(abs(v))) > EXTREME_EXPONENT for v in values.values()):
        return None
    when = "in its first step" if len(run.t) <= 1 else f"by t = {float(run.t[-1]):.4g} s"
    return overflow_error(values, [], f"the motion overflows double precision {when}")


def _too_large(c: CompiledScene, params: list[float], req: Any, what: str) -> dict[str, str]:
    """Name the parameters or initial values that overflowed (the overridden ones, when none
    is extreme)."""
    values = {f"parameters.{k}": v for k, v in zip(c.parameters, params, strict=True)}
    values |= {f"initial.{k}": v for k, v in req.initial.items()}
    named = [f"parameters.{k}" for k in req.parameters] + [f"initial.{k}" for k in req.initial]
    verb = "overflow" if what == "the accelerations q̈" else "overflows"
    return overflow_error(values, named, f"{what} {verb} double precision at the start")


def _singular_mass(c: CompiledScene, params: list[float], names: str) -> dict[str, str]:
    """Name the parameters that make M singular (a zero mass), else the state (a pole)."""
    m = c.derivation.model
    used = {str(s) for s in c.derivation.work.mass_matrix.free_symbols}
    culprits = [k for k, v in zip(c.parameters, params, strict=True) if k in used and v <= 0]
    if culprits:
        return {
            "field": ", ".join(f"parameters.{k}" for k in culprits),
            "message": "must be > 0: with "
            + ", ".join(
                f"{k} = {v:g}" for k, v in zip(c.parameters, params, strict=True) if k in culprits
            )
            + " the mass matrix is singular (a coordinate has no inertia), so q̈ is undefined",
        }
    return {
        "field": names,
        "message": "the mass matrix is singular (or not positive definite) in this state: the "
        f"coordinates {', '.join(m.coordinate_names)} are singular here (like φ at θ = 0 of "
        "spherical coordinates) or a mass or inertia is not positive; start elsewhere",
    }


class _OtherBranch(Exception):
    """The state lies on the other side of some springs' anchors: derive that variant."""

    def __init__(self, flips: dict[int, int]) -> None:
        self.flips = flips


def _run(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    t_eval: np.ndarray,
    req: SimulationRequest,
    rtol: float,
    atol: float,
) -> Trajectory:
    """One integration of the request's method, or of the one that must run instead
    (mechanics/scene_run.py says when and why; ``run.method`` names the one that ran)."""
    kw = {"method": req.method, "dt": req.dt, "max_wall_time": MAX_WALL_TIME}
    return run_scene(c, params, y0, t_eval, rtol=rtol, atol=atol, **kw)


def fixed_step_grid(t_end: float, fps: float, dt: float) -> tuple[np.ndarray, int]:
    """Sample times for a fixed-step run, and the steps between two samples.

    The run takes exactly the step asked for: a student picks dt to see what it costs and how
    accurate it is, and steps squeezed to land on a 1/fps grid would be another method's run.
    So the samples are every `stride` steps, a whole number near 1/(fps·dt) (one step when dt
    is longer than 1/fps), preferably one that divides the steps to t_end, so the last sample
    is the last step. The sample spacing is then stride·dt, not 1/fps: clients read the times
    from ``t``.
    """
    total = math.floor(t_end / dt + 1e-9)  # whole steps of dt within t_end
    if total < 1:
        return np.zeros(1), 1
    ideal = 1.0 / (fps * dt)
    fewest = math.ceil(total / (MAX_SAMPLES - 1))  # the smallest stride within MAX_SAMPLES
    stride = max(1, round(ideal), fewest)
    if ideal > 1:  # divisors of `total` within a factor 2 of the ideal, nearest (in ratio) first
        lo, hi = max(1, math.ceil(ideal / 2), fewest), min(total, math.floor(2 * ideal))
        candidates = [d for d in range(lo, min(hi, lo + 4000) + 1) if total % d == 0]
        if candidates:
            stride = min(candidates, key=lambda d: abs(math.log(d / ideal)))
    n = total // stride + 1
    return np.arange(n) * (stride * dt), stride


def _sample_times(req: SimulationRequest) -> np.ndarray:
    if METHODS[req.method].kind == "fixed":
        return fixed_step_grid(req.t_end, req.fps, req.dt)[0]
    n_samples = int(math.floor(req.t_end * req.fps + 1e-9)) + 1
    return np.linspace(0.0, (n_samples - 1) / req.fps, n_samples)


def _where_samples_end(req: SimulationRequest, t_eval: np.ndarray) -> list[str]:
    """Say where the samples end when it is short of t_end (they start at 0 on a fixed grid)."""
    short = req.t_end - float(t_eval[-1])
    if not short > 1e-9 * max(1.0, req.t_end):
        return []
    if METHODS[req.method].kind == "fixed":
        spacing = float(t_eval[1] - t_eval[0]) if len(t_eval) > 1 else req.dt
        stride = max(1, round(spacing / req.dt))
        return [
            f"The steps are dt = {req.dt:.6g} s and the samples every {stride} step"
            f"{'s' if stride > 1 else ''} ({spacing:.4g} s apart), so the run ends at the last "
            f"sample, t = {t_eval[-1]:.6g} s, {short:.3g} s short of t_end = {req.t_end:.6g} s: "
            "ask for a t_end that is a whole number of steps to get the state at t_end."
        ]
    return [
        f"Samples are 1/fps = {1 / req.fps:.4g} s apart, so the last is at "
        f"t = {t_eval[-1]:.6g} s, {short:.3g} s short of t_end = {req.t_end:.6g} s: ask for "
        "a t_end that is a multiple of 1/fps (or a higher fps) to get the state at t_end."
    ]


def simulate_compiled(c: CompiledScene, req: SimulationRequest) -> dict[str, Any]:
    params, y0 = check_request(c, req)
    t_eval = _sample_times(req)
    refuse_passed_stops(c, params, y0)
    at_start = stopped_at_start(c, params, y0, req.t_end)
    run = _run(c, params, y0, t_eval[:1] if at_start else t_eval, req, req.rtol, req.atol)
    warnings: list[str] = [run.note] if run.note else []
    warnings += _where_samples_end(req, t_eval)
    if at_start is None:
        warnings += _implicit_on_a_jump(c, params, y0, req)
    raw = run
    if at_start is not None:
        run.status, run.message = "stopped", f"{at_start.name} at t = 0 s"
    stop = first_stop(c, run, params, req, run.watch) if at_start is None else None
    if at_start is not None:
        stop = StopEvent(at_start.name, at_start.message, 0.0, run)
    if stop is not None:
        run = stop.run
    # a limit written in t or q that the run carries below 0 (k (x − 1) past x = 1): named
    # first, since a failure past it is that limit's doing, not a force's or a stiffness's
    values = dict(zip(c.parameters, params, strict=True))
    n = c.n
    t_seen, y_seen = run.t, run.y
    reached = _state_reached(c, params, req, run) if run.status != "ok" else None
    if reached is not None:
        # a failed run's last step lies past its last sample: a mass "m (1 − t/2)" reaches 0
        # at the failure (t = 2 s) and at no sample before it
        t_seen = np.append(run.t, run.t_reached)
        y_seen = np.vstack([run.y, reached[None, : run.y.shape[1]]])
    unphysical = limits_along_run(
        c.derivation.model, values, t_seen, y_seen[:, :n].T, y_seen[:, n : 2 * n].T
    )
    warnings += unphysical
    if stop is not None:
        warnings.append(f"Stopped at t = {stop.t:.4g} s: {stop.message}.")
    elif run.status != "ok":
        overflow = _overflowed(c, params, req, run)
        if overflow is not None and len(run.t) <= 1:  # not one step: as a start that overflows
            raise SpecError([overflow])
        said = run.message.rstrip(".")  # scipy's messages end in a full stop of their own
        warnings.append(f"The run stopped early: {said}. The trajectory is partial.")
        if unphysical:
            pass  # the limit's warning says why: a blow-up's or stiffness's advice would mislead
        elif overflow is not None:
            warnings.append(overflow["message"][0].upper() + overflow["message"][1:] + ".")
        else:
            warnings += _why_it_stopped(c, params, req, run)
    t, y = run.t, run.y
    n = c.n
    q, qd, w_nc = y[:, :n].T, y[:, n : 2 * n].T, y[:, 2 * n]
    T, V = evaluate(c.energy, t, q, qd, params)
    E = T + V
    # at a domain's end (x = l√θ at θ = 0) T = m l² θ̇²/(8θ) is 0/0 in doubles: the located
    # state's energy is no measure of the run's accuracy, the samples before it are
    measured = len(t) - 1 if stop is not None and stop.kind == "domain" and len(t) > 1 else len(t)
    w_drive = np.zeros_like(t)
    if c.drive is not None:
        (e_minus_h,) = evaluate(c.drive, t, q, qd, params)
        w_drive = e_minus_h - e_minus_h[0] + (y[:, 2 * n + 1] if c.extras > 1 else 0.0)
    # E − h constant (the conserved step proved it: a puck on a turntable, E − h = Ω p_φ): the
    # frame's drive does no work, though E − h ≠ 0 and W_drive is computed as rounding noise
    verdict = next((s.data or {} for s in c.derivation.steps if s.id == "conserved"), {})
    idle_drive = verdict.get("drive_work") == "none"
    stats: dict[str, Any] = {
        "method": raw.method or req.method,  # the method that ran (scene_run.py)
        "method_requested": req.method,
        "steps": run.nsteps,
        "rhs_evaluations": run.nfev,
        "jacobian_evaluations": run.njev,
        "wall_time": run.wall_time,
        "samples": len(t),
        "sample_interval": float(t_eval[1] - t_eval[0]) if len(t_eval) > 1 else None,
        "status": run.status,
        "driven": c.drive is not None and not idle_drive,
    }
    if METHODS[req.method].kind == "fixed":
        # the step the run took, dt to rounding (samples are whole steps apart); the asked dt
        # when no step was taken (a zero-length run, a stop at t = 0)
        taken = run.step if math.isfinite(run.step) else req.dt
        stats["dt"] = req.dt if abs(taken - req.dt) <= 1e-9 * req.dt else taken
        if stats["dt"] != req.dt:  # the grid is built so that this never happens
            warnings.append(f"The step taken was {taken:.6g} s, not dt = {req.dt:.6g} s.")
    if stop is not None:
        stats["stop"] = {"name": stop.name, "t": stop.t, "message": stop.message}
    scale = max(float(np.max(np.abs(T[:measured]))) if len(T) else 0.0, 1e-300)
    conserved = {x["name"] for x in c.derivation.work.conserved}
    if "energy" in conserved:
        stats["energy_error"] = float(np.max(np.abs(E[:measured] - E[0]))) / scale
    elif c.jacobi is not None:
        (h,) = evaluate(c.jacobi, t, q, qd, params)
        stats["jacobi_error"] = float(np.max(np.abs(h[:measured] - h[0]))) / scale
    else:
        # ΔT + ΔV = W_NC + W_drive (notes III): every agent that does work is on the right.
        balance = E - E[0] - w_nc - w_drive
        stats["energy_balance_error"] = float(np.max(np.abs(balance[:measured]))) / scale
    drift = {}
    for name, fn in c.momenta.items():
        (p,) = evaluate(fn, t, q, qd, params)
        drift[name] = float(np.max(np.abs(p[:measured] - p[0]))) / max(
            float(np.max(np.abs(p[:measured]))), 1e-300
        )
    stats["momentum_drift"] = drift
    noise = roundoff(c, t, q, qd, params, T, [w_nc, w_drive])[:measured]
    if "energy" in conserved:
        said = _accuracy_warning(req, "E", E - E[0], E[0], T, t, qd, c, measured, noise, params)
    elif c.jacobi is not None:
        said = _accuracy_warning(
            req, "The Jacobi integral h", h - h[0], h[0], T, t, qd, c, measured, noise, params
        )
    else:
        said = _accuracy_warning(req, _BALANCE, balance, None, T, t, qd, c, measured, noise, params)
    warnings += [said] if said else []
    warnings += _singularity_warnings(c, t, q, qd, params)
    if req.check_sensitivity and METHODS[req.method].kind == "adaptive" and raw.status == "ok":
        warnings += _sensitivity(c, params, y0, t_eval, req, run)
    positions = {
        name: dict(zip("xyz", evaluate(fn, t, q, qd, params), strict=True))
        for name, fn in c.places.items()
    }
    # a run cut at a stop ends on its surface, located to the tolerance: at a domain's end (√θ
    # at θ = 0) that state may lie a round-off past it, which is the stop's, not a departure
    shown = len(t) - 1 if stop is not None else len(t)
    warnings += _outside_domain(c, t[:shown], q[:, :shown], _first(positions, shown))
    frames = {
        name: np.stack(evaluate(fn, t, q, qd, params), axis=1) for name, fn in c.frames.items()
    }
    work = _work(c, t, q, qd, params)
    extra: dict[str, Any] = {}
    if req.constraint_forces:
        extra["constraint_forces"] = _constraint_forces(c, t, q, qd, params, warnings)
    forces = [
        {
            "label": label,
            "kind": kind,
            "on": on,
            **dict(zip("xyz", (v.tolist() for v in evaluate(fn, t, q, qd, params)), strict=True)),
        }
        for label, kind, on, fn in c.forces
    ]
    return {
        **extra,
        "forces": forces,
        "work": work,
        "t": t.tolist(),
        "q": {name: q[i].tolist() for i, name in enumerate(c.coordinates)},
        "q_dot": {name: qd[i].tolist() for i, name in enumerate(c.coordinates)},
        "energy": {
            "T": T.tolist(),
            "V": V.tolist(),
            "E": E.tolist(),
            "W_nc": w_nc.tolist(),
            "W_drive": w_drive.tolist(),
        },
        "positions": {k: {a: v.tolist() for a, v in xyz.items()} for k, xyz in positions.items()},
        "frames": {k: v.tolist() for k, v in frames.items()},
        "stats": stats,
        "warnings": warnings,
    }


_BALANCE = "The energy balance ΔT + ΔV − W_NC − W_drive (0 for an exact run)"

#: Units in the last place that evaluating T + V (and the work terms) may cost: the energy of a
#: sample is a sum of terms each rounded to its own size, so its error is a few ulps of the
#: largest term, not of the sum. A pendulum of m = 1000 kg swinging by 1e-7 rad has |V| = 9810 J
#: and T ≤ 5e-11 J: one ulp of V (1.8e-12 J) is 3.7 % of T, and no tolerance can shrink it.
ROUNDOFF_ULPS = 4
#: An error within this many times the round-off floor may be half round-off or more: advice to
#: tighten the tolerance (or shorten the step) would promise more than it can give.
ROUNDOFF_SHARE = 2


def roundoff(c: CompiledScene, t, q, qd, params, T: np.ndarray, work: list) -> np.ndarray:
    """The error floating point alone puts into each sample's T + V (− W): ROUNDOFF_ULPS ulps of
    the sum of the terms' sizes, |T| + Σ|V_part| (+ |W|), since a large V that cancels (a mass
    hung 1000 m above the datum) is rounded at its own size before the cancellation."""
    size = np.abs(T)
    for fn in c.potential_parts.values():
        (part,) = evaluate(fn, t, q, qd, params)
        size = size + np.abs(part)
    for w in work:
        size = size + np.abs(w)
    return ROUNDOFF_ULPS * np.finfo(float).eps * size


def _accuracy_warning(
    req: SimulationRequest,
    name: str,
    error: np.ndarray,
    start: float | None,
    T: np.ndarray,
    t: np.ndarray,
    qd: np.ndarray,
    c: CompiledScene,
    measured: int,
    noise: np.ndarray | None,
    params: list[float],
) -> str | None:
    """The sentence on a run whose conserved quantity (or energy balance) strayed by more than
    ENERGY_WARNING, true to what the error did: a symplectic method's error oscillates and stays
    bounded however long the run (a smaller step shrinks it, a longer run does not grow it), an
    explicit one's grows with time; advice that fits one is wrong for the other.

    ``error`` is the signed error at each sample (Q − Q0, or the balance residual), ``start``
    is Q0 (None for the balance, whose exact value is 0); ``noise`` the round-off floor of each
    sample (`roundoff`): an error within the floor of its sample and of the start is no
    integration error and no tolerance or step shrinks it, so it is not warned about, and where
    round-off is a sizeable share of the error the advice says so instead of promising a cure."""
    error, T, t, qd = error[:measured], T[:measured], t[:measured], qd[:, :measured]
    if len(error) == 0 or not (np.all(np.isfinite(error)) and np.all(np.isfinite(T))):
        return None
    floor = np.zeros_like(error) if noise is None else noise[: len(error)] + noise[0]
    if np.all(np.abs(error) <= floor):
        return None
    # Sized against the kinetic energy each sample would have had were the quantity exact,
    # T − error (E0 − V where E is conserved): the error cannot inflate it. The largest T of
    # the run itself can: explicit Euler's pendulum at t_end = 100 went from 4.1 J to 51 J and
    # max T with it, so |ΔE| / max T read 0.78 for an energy that grew twelvefold.
    scale = float(np.max(T - error))
    worst = int(np.argmax(np.abs(error)))
    size = abs(float(error[worst])) / scale if scale > 1e-300 else 0.0
    if not size > ENERGY_WARNING:
        return None
    unit = " J" if c.derivation.model.spec.units else ""
    method = METHODS[req.method]
    fixed = method.kind == "fixed"
    shrink = "a smaller step" if fixed else "a tighter rtol/atol"
    share = f"{100 * size:.2g}% of" if size < 1 else f"{size:.2g} times"
    of_scale = f"{share} the motion's kinetic-energy scale ({scale:.3g}{unit})"
    largest_floor = float(np.max(floor))
    if abs(float(error[worst])) < ROUNDOFF_SHARE * largest_floor:
        return (
            f"{name} strays by up to {abs(float(error[worst])):.3g}{unit}, {of_scale}; "
            f"floating-point round-off of the sum T + V alone can reach "
            f"{largest_floor:.2g}{unit} (its terms are far larger than the motion's energy), "
            f"so {shrink} would not remove much of it."
        )
    trend = _error_trend(error, qd)
    if trend == "bounded":
        lo, hi = float(np.min(error)), float(np.max(error))
        if start is not None:
            lo, hi = lo + start, hi + start
        symplectic = method.symplectic and why_not_symplectic(c, params) is None
        why = "a symplectic method's bounded error" if symplectic else "a bounded error"
        return (
            f"{name} oscillates between {_apart(lo, hi, lo)}{unit} and {_apart(hi, lo, hi)}{unit}, "
            f"within {of_scale}, "
            f"and does not grow over the run: {why}; {shrink} shrinks it."
        )
    if start is None:  # the balance: 0 for an exact run, so no "from"
        change = f"reached {float(error[worst]):.3g}{unit}"
    else:
        end = start + float(error[worst])
        moved = "grew" if error[worst] > 0 else "fell"
        change = (
            f"{moved} from {_apart(start, end, start)}{unit} to {_apart(start, end, end)}{unit}"
        )
    when = f"by t = {t[worst]:.3g} s"
    if trend == "grows":
        not_here = why_not_symplectic(c, params) if fixed else None
        if method.symplectic and not_here:
            better = (
                f"take {shrink} or a higher-order method ({req.method} is not symplectic here: "
                f"{not_here})"
            )
        elif method.symplectic:
            better = f"take {shrink}"
        elif fixed and not not_here:
            better = (
                f"take {shrink}, or a symplectic method (symplectic_euler, implicit_midpoint) "
                "whose energy error stays bounded for this scene's constant mass matrix"
            )
        elif fixed:
            better = f"take {shrink} or a higher-order method"
        else:
            better = f"ask for {shrink} or a higher-order method"
        return (
            f"{name} drifts: it {change} {when}, {of_scale}, and the error grows with the "
            f"length of the run: {better}."
        )
    return f"{name} {change} {when}, {of_scale}: ask for {shrink} or a higher-order method."


def why_not_symplectic(c: CompiledScene, params: list[float]) -> str | None:
    """Why symplectic Euler and the implicit midpoint step do not keep a modified energy on this
    motion, in the words the page shows; None where they do. One rule for every claim of a
    bounded energy error (the methods' rows, the long run).

    They do on the flow of a Hamiltonian H(q, p) free of t, stepped in variables that are a
    linear change of (q, p): L free of t, no power of the non-conservative forces (judged at
    these parameters: a damper with c = 0 does no work), M constant (p = M q̇), and q̈ free of
    q̇ (their explicit update of q̇ is the symplectic one only for forces of q alone). A damped,
    driven or rubbing motion conserves no energy at all (the error measured is the energy
    balance's), so there is nothing for a modified energy to stay close to."""
    m, work = c.derivation.model, c.derivation.work
    values = {
        m.params[name]: sp.Rational(repr(float(v)))
        for name, v in zip(c.parameters, params, strict=True)
    }
    Q = [_expr(q).xreplace(values) for q in work.Q]
    power = sp.expand(sum((q * qd for q, qd in zip(Q, m.qd, strict=True)), sp.S.Zero))
    if not vanishes(power, m):
        return (
            "non-conservative forces do work on this motion (a damper, friction or a driving "
            "force: Σ Q_j q̇_j ≠ 0), so its energy is not conserved and there is no conserved "
            "energy for symplectic Euler to stay close to; the error shown is that of the energy "
            "balance ΔT + ΔV − W_NC, which is not bound to stay bounded"
        )
    if explicit_time(work.L.xreplace(values), m):
        return (
            "L depends explicitly on t (a driven or moving support), so no energy is conserved "
            "and there is no fixed Hamiltonian whose modified version symplectic Euler could keep"
        )
    if not constant_mass_matrix(c):
        return (
            "the mass matrix changes with the coordinates, so symplectic Euler, which steps q and "
            "q̇ rather than the momenta p = M(q) q̇, is not symplectic here: its energy error is "
            "not bound to stay bounded"
        )
    forcing = work.forcing if work.forcing is not None else work.accelerations
    if forcing is None:
        return "the equations were too large to check whether the forces depend on q̇ or on t"
    for f in forcing:
        f = _expr(f).xreplace(values)
        if f.has(*m.qd) or explicit_time(f, m):
            return (
                "the forces depend on the velocities (a gyroscopic force, like a magnetic one), "
                "and symplectic Euler's explicit update of q̇ is not the symplectic map of such "
                "a flow"
            )
    return None


def _expr(x: Any) -> sp.Expr:
    """A sympy number or expression as it is; a plain 0 (a Q_j no force contributes to) as one."""
    return x if isinstance(x, sp.Basic) else sp.Integer(x)


def constant_mass_matrix(c: CompiledScene) -> bool:
    """Whether M is free of the coordinates and t. symplectic_euler (v ← v + h a, q ← q + h v)
    and implicit_midpoint step (q, q̇), not (q, p): only when M is constant is that a linear
    change of the canonical variables, so only then are they symplectic (on the double
    pendulum symplectic_euler's E drifts from 0.149 J to −26.5 J by t = 60 s)."""
    m = c.derivation.model
    M = c.derivation.work.mass_matrix
    return M is not None and not any(entry.has(T_SYMBOL, *m.q) for entry in M)


def _apart(a: float, b: float, x: float) -> str:
    """x with the digits that tell a from b apart (E fell from −8.7312 J to −8.7225 J, not from
    −8.73 J to −8.73 J), at least 3 significant."""
    gap, size = abs(a - b), max(abs(a), abs(b))
    digits = 3 if gap == 0 or size == 0 else max(3, min(12, math.ceil(math.log10(size / gap)) + 2))
    return f"{x:.{digits}g}"


#: A drift: the error's size over the second half of the run exceeds the first half's by more
#: than this, and never comes back below half of the first half's largest. A linear drift
#: doubles from one half to the next, explicit Euler's at least that.
DRIFT_GROWTH = 1.25
#: A bounded oscillation reaches the same floor and the same ceiling in both halves of the run,
#: to this share of its range: a symplectic method's does (the simple pendulum's to 1e-3), while
#: a secular trend moves the floor or ceiling, whether or not the peaks grow (explicit Euler on
#: the double pendulum: peaks 60 J → 76 J, floor −0.7 J → 30 J).
SAME_ENVELOPE = 0.1
#: A secular trend: the mean of the signed error moves by more than this share of the first
#: half's range, the same way through each quarter of the run. A bounded oscillation with at
#: least a swing in each half moves its half-means by at most about a third of its range.
TREND_SHIFT = 0.5
#: The same, with a floor risen this share of the first half's range clear of 0 over the whole
#: second half.
FLOOR_SHIFT = 0.25


def _error_trend(error: np.ndarray, qd: np.ndarray) -> str:
    """ "grows", "bounded" or "unknown": "bounded" only when nothing a growing error would do
    shows (the floor, the ceiling and the peaks of the second half all those of the first), so
    no criterion a drift can pass calls it bounded; "unknown" tells the numbers alone.

    Told only when the first half holds at least a swing (two turning points of some velocity):
    before that a bounded error has not shown its range, and an oscillation still rising to its
    first peak would read as a drift."""
    half = len(error) // 2
    if half < 8 or _turning_points(qd[:, :half]) < 2:
        return "unknown"
    first, second = error[:half], error[half:]
    size = np.abs(error)
    peak1, peak2 = float(np.max(size[:half])), float(np.max(size[half:]))
    if peak2 > DRIFT_GROWTH * peak1 and float(np.min(size[half:])) > 0.5 * peak1:
        return "grows"
    lo1, hi1 = float(np.min(first)), float(np.max(first))
    lo2, hi2 = float(np.min(second)), float(np.max(second))
    spread = max(hi1 - lo1, 1e-300)
    means = [float(np.mean(part)) for part in np.array_split(error, 4)]
    steps = np.diff(means)
    monotone = bool(np.all(steps > 0) or np.all(steps < 0))
    shift = means[-1] - means[0]
    if monotone and abs(shift) > TREND_SHIFT * spread:
        return "grows"
    # a floor (or ceiling) that has left the start behind: the error started at 0 and the whole
    # second half stays off it on the trend's side (explicit Euler, double pendulum: ≥ 24.5 J
    # after a first half spanning −0.85 J to 75 J); a bounded oscillation comes back to its start
    off = lo2 if shift > 0 else -hi2
    if monotone and abs(shift) > FLOOR_SHIFT * spread and off > FLOOR_SHIFT * spread:
        return "grows"
    same = abs(lo2 - lo1) <= SAME_ENVELOPE * spread and abs(hi2 - hi1) <= SAME_ENVELOPE * spread
    if same and peak2 <= DRIFT_GROWTH * peak1 and float(np.min(size[half:])) < 0.5 * peak2:
        return "bounded"
    return "unknown"


def _turning_points(qd: np.ndarray) -> int:
    """Most sign changes of any one velocity; round-off around 0 (a coordinate that does not
    move, a start from rest) is no turning."""
    most = 0
    for v in qd:
        big = np.abs(v) > 1e-6 * float(np.max(np.abs(v), initial=0.0))
        s = np.sign(v[big])
        most = max(most, int(np.count_nonzero(s[1:] != s[:-1])))
    return most


def _work(c, t, q, qd, params) -> dict[str, dict[str, list[float]]]:
    """Cumulative work of each force since t = 0 (notes eq. 22–23).

    A conservative force's work is −ΔV of its part of V, exactly; a non-conservative force's is
    the integral of its power F·v over the samples (cumulative Simpson, so it is as accurate as
    the output rate allows; the run's W_nc is the exact one, integrated with the motion).
    """
    out: dict[str, dict[str, list[float]]] = {"conservative": {}, "non_conservative": {}}
    for name, fn in c.potential_parts.items():
        (v,) = evaluate(fn, t, q, qd, params)
        out["conservative"][name] = (-(v - v[0])).tolist()
    for name, fn in c.powers.items():
        (p,) = evaluate(fn, t, q, qd, params)
        if len(t) >= 3:
            w = np.concatenate([[0.0], cumulative_simpson(p, x=t)])
        else:
            w = np.concatenate([[0.0], np.cumsum(np.diff(t) * (p[1:] + p[:-1]) / 2)])
        out["non_conservative"][name] = w.tolist()
    return out


def _outside_domain(c: CompiledScene, t: np.ndarray, q: np.ndarray, positions: dict) -> list[str]:
    """A body's position undefined at a finite state (l*sqrt(θ) once θ < 0): the equations
    may run on, finite, but past that sample they describe no position of the system."""
    finite_q = np.all(np.isfinite(q), axis=0)
    for name, xyz in positions.items():
        with np.errstate(invalid="ignore"):
            bad = finite_q & ~np.all(
                [np.isfinite(np.asarray(v, dtype=float)) for v in xyz.values()], axis=0
            )
        if bad.any():
            i = int(np.argmax(bad))
            at = ", ".join(f"{n} = {q[j][i]:.4g}" for j, n in enumerate(c.coordinates))
            return [
                f"At t = {t[i]:.4g} s ({at}) the position of {name} is undefined: the state has "
                "left the domain of its position function (e.g. a square root of a negative "
                "number). The motion from there on is not the system's."
            ]
    return []


def _first(positions: dict, k: int) -> dict:
    return {name: {a: v[:k] for a, v in xyz.items()} for name, xyz in positions.items()}


def _constraint_forces(c, t, q, qd, params, warnings) -> dict[str, dict[str, list[float]]]:
    """R = m a − ΣF along the run; a rod's tension, and where a string would go slack."""
    from mechanics.newton_potentials import unknown_constraint_forces

    out = {}
    unknown = unknown_constraint_forces(c.derivation.model, plain=True)
    if unknown is not None:  # a potential V(q): none is computed, and the run says why
        warnings.append(unknown)
    for body, (fn, tension_fn) in constraint_force_functions(c).items():
        x, y, z = evaluate(fn, t, q, qd, params)
        out[body] = {"x": x.tolist(), "y": y.tolist(), "z": z.tolist()}
        if tension_fn is not None:
            (tension,) = evaluate(tension_fn, t, q, qd, params)
            out[body]["tension"] = tension.tolist()
            slack = np.nonzero(tension < 0)[0]
            if len(slack):
                warnings.append(
                    f"The tension on {body} turns negative at t = {t[slack[0]]:.3g} s: a rod "
                    "pushes there, but a string would go slack and the motion would change."
                )
    return out


#: How much |T| + |V| must have grown, from the first half of a run to where it stopped, for a
#: failed run to be told as a blow-up rather than as stiffness. Energy, not the size of the state:
#: a stiff spring's velocity rises from 0 to ωx₀ within a step of its start, its energy stays.
BLOW_UP_GROWTH = 1e6


def _why_it_stopped(c: CompiledScene, params: list[float], req: Any, run: Trajectory) -> list[str]:
    """Advice for a run that stopped early, from what the state did (values of ordinary size).

    A solution that grows without bound (ẍ = −4x + 0.1ẋ³ blows up in finite time) makes an
    adaptive solver's steps shrink to nothing, as stiffness does; told "try Radau or BDF" a
    student would chase the wrong cause. Stiffness keeps the state bounded and makes h·ρ(J) of
    order 1 (`_looks_stiff`); a blow-up makes the state's size explode. A fixed step that
    overflows cannot tell a fast but finite motion (φ̇ near the pole of spherical coordinates)
    from a blow-up: it says both, and how to find out.
    """
    text = run.message.lower()
    explicit = not METHODS[req.method].implicit
    t_stop = run.t_reached if math.isfinite(run.t_reached) else float(run.t[-1])
    ran_away = "overflow" in text or "non-finite" in text
    if METHODS[req.method].kind == "fixed" and ran_away:
        return [
            f"With a fixed step of dt = {req.dt:g} s the state ran away within a step near "
            f"t = {t_stop:.4g} s. That happens where the motion is fast for the step (near a "
            "coordinate singularity, like θ = 0 of spherical coordinates where φ̇ is large) or "
            "where the solution itself grows without bound: try a smaller dt, or an adaptive "
            "method (DOP853), which shrinks its steps where the motion is fast and tells the two "
            "apart."
        ]
    jumps = [u for u, _ in velocity_jump_functions(c)]
    held_down = any(w in text for w in ("wall-time", "budget", "step size", "too small"))
    if jumps and held_down:
        u = jumps[0]
        return [
            f"The steps were held down at a jump of the equations, not by stiffness: sign({u}) "
            f"changes the force at once where {u} = 0 (friction reversing). Where the other "
            "forces cannot overcome the friction the contact sticks, and the equations, read "
            "with sign(0) = 0, describe it only while it slides: the steps chatter across "
            f'{u} = 0. Declare a stop on {u} (crossing "any", with only_if the condition for '
            "sliding on) to end the run where it sticks; Radau or BDF do not help."
        ]
    # out of wall time, a growing state may be a resonance still climbing, not a blow-up
    growth = None if "wall-time" in text else _growth(c, params, req, run)
    if growth is not None:
        before, after = growth
        return [
            f"The solution grows without bound: |T| + |V| went from {before:.3g} (first half "
            f"of the run) to {after:.3g} at t = {t_stop:.4g} s, where the steps "
            "shrank to nothing. That is a blow-up in finite time, the equations' own motion and "
            "not stiffness: no method or tolerance carries it further (look for a force that "
            "feeds energy in faster than the motion grows, like + c·ẋ³)."
        ]
    if "wall-time" in text:  # out of time: stiffness, or a busy server
        stiff = explicit and _looks_stiff(c, params, run)
        return [
            f"The run took longer than its {MAX_WALL_TIME:g} s of wall time"
            + (
                ": its steps were held down by the fastest mode (a stiff system), where an "
                "explicit method needs tiny steps: try Radau or BDF."
                if stiff
                else " (the server may have been busy): try again, or ask for less (a "
                "shorter t_end, a looser rtol, dop853_c)."
            )
        ]
    if "budget" in text or "step size" in text or "too small" in text:
        if explicit and _looks_stiff(c, params, run):
            return ["This looks stiff for an explicit method: try Radau or BDF."]
        if "budget" in text:
            return ["The run used up its steps: ask for less (a shorter t_end, a looser rtol)."]
        return [
            f"The solver's steps shrank to nothing near t = {t_stop:.4g} s while the state "
            "stayed bounded: the equations are not smooth there (a discontinuity such as "
            "friction reversing, or a singularity of the coordinates)."
        ]
    return []


#: Methods whose Newton iterations use a finite-difference Jacobian from the first step: across
#: sign(ẋ) at ẋ = 0 it reads the jump as an enormous damping (LSODA starts explicit and switches
#: only when it finds the problem stiff: it slid correctly where these two crept or ran off).
_NEWTON_FROM_THE_START = ("Radau", "BDF")


def _implicit_on_a_jump(c: CompiledScene, params: list[float], y0: np.ndarray, req) -> list[str]:
    """A run by Radau or BDF that starts at u = 0 of a sign(u) of a velocity (a block released
    from rest against Coulomb friction): Radau crept (x from 5 to 4.97 in 10 s where the block
    slides to 0.886 by t = π), BDF ran off to x = −245. Said, with the methods that do not."""
    if req.method not in _NEWTON_FROM_THE_START:
        return []
    n = c.n
    out = []
    for text, fn in velocity_jump_functions(c):
        try:
            value = float(fn(0.0, *y0[:n].tolist(), *y0[n : 2 * n].tolist(), *params))
        except (ValueError, ZeroDivisionError, OverflowError):
            continue
        if value == 0:
            out.append(
                f"The run starts at {text} = 0, where sign({text}) (the friction) jumps: "
                f"{req.method}'s Newton iterations straddle the jump, and their finite-"
                "difference Jacobian reads it as an enormous damping, so the motion shown may "
                "creep or run off instead of sliding. Run it with an explicit method (DOP853, "
                "RK45) or LSODA."
            )
    return out


def _state_reached(c: CompiledScene, params: list[float], req: Any, run: Trajectory):
    """The state where a failed run's stepping stopped (past its last sample), or None. The C
    loop keeps no state past its last sample: the stretch from there is stepped again (scipy's
    DOP853), so a limit reached there (a mass m (1 − t) at t = 1) is seen by every method."""
    if run.y_reached is not None:
        return np.asarray(run.y_reached, dtype=float) if math.isfinite(run.t_reached) else None
    t_last, reached = float(run.t[-1]), run.t_reached
    if not (math.isfinite(reached) and reached > t_last):
        return None
    try:
        again = integrate(
            c.rhs(params),
            run.y[-1],
            np.array([t_last, reached]),
            method="DOP853",
            rtol=req.rtol,
            atol=req.atol,
            max_wall_time=1.0,
            second_order=c.n,
        )
    except (ValueError, *_PHYSICAL):
        return None
    return None if again.y_reached is None else np.asarray(again.y_reached, dtype=float)


def _growth(c: CompiledScene, params: list[float], req: Any, run: Trajectory):
    """(|T| + |V| before, at the stop) when it grew BLOW_UP_GROWTH-fold from the first half of
    the run to where the stepping stopped; else None."""
    n2 = 2 * c.n
    t_last, reached = float(run.t[-1]), run.t_reached
    end = _state_reached(c, params, req, run)
    end = np.asarray(run.y[-1] if end is None else end, dtype=float)
    early = run.t <= (reached if math.isfinite(reached) else t_last) / 2

    def size(t: np.ndarray, y: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            T, V = evaluate(c.energy, t, y[:, : c.n].T, y[:, c.n : n2].T, params)
        return np.abs(T) + np.abs(V)

    before = float(np.max(size(run.t[early], run.y[early])))
    at = reached if math.isfinite(reached) else t_last
    after = float(size(np.array([at]), end[None, :])[0])
    if math.isnan(after) or not after > BLOW_UP_GROWTH * max(before, 1e-300):
        return None
    return before, after


def _looks_stiff(c: CompiledScene, params: list[float], run: Any) -> bool:
    """Were the explicit steps limited by stability rather than accuracy? Then h·ρ(J), the mean
    step times the fastest rate of the linearized motion where the run ended, is of order 1 (an
    explicit Runge–Kutta method is stable only for |hλ| ≲ 3); for steps held down by accuracy it
    is far smaller."""
    n = c.n
    reached = run.t_reached if math.isfinite(run.t_reached) else run.t[-1]
    if run.nsteps < 1 or not reached > run.t[0]:
        return False
    f, y = c.rhs(params), np.array(run.y[-1], dtype=float)
    try:
        with np.errstate(all="ignore"):
            base = np.asarray(f(run.t[-1], y), dtype=float)[: 2 * n]
            jac = np.empty((2 * n, 2 * n))
            for j in range(2 * n):
                e = 1.4901161193847656e-08 * max(1.0, abs(y[j]))
                probe = y.copy()
                probe[j] += e
                jac[:, j] = (np.asarray(f(run.t[-1], probe), dtype=float)[: 2 * n] - base) / e
            rho = float(np.max(np.abs(np.linalg.eigvals(jac))))
    except (*_PHYSICAL, ValueError):
        return False
    h = (reached - run.t[0]) / run.nsteps
    return math.isfinite(rho) and h * rho > 0.5


def _singularity_warnings(c, t, q, qd, params) -> list[str]:
    """A nearly singular mass matrix marks a coordinate singularity (θ → 0 on a sphere)."""
    n = c.n
    flat = evaluate(c.mass_matrix, t, q, qd, params)
    M = np.stack(flat, axis=-1).reshape(len(t), n, n)
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(M) if n > 1 else np.ones(len(t))
        if n == 1:
            cond = np.where(M[:, 0, 0] == 0, np.inf, 1.0)
    bad = np.nonzero(~np.isfinite(cond) | (cond > 1e8))[0]
    if not len(bad):
        return []
    i = bad[0]
    return [
        f"The mass matrix is nearly singular at t = {t[i]:.3g} s (condition number "
        f"{cond[i]:.1e}): the coordinates are singular there (e.g. θ → 0 of spherical "
        "coordinates), so accelerations of the other coordinates are ill-determined."
    ]


def _sensitivity(c, params, y0, t_eval, req, run) -> list[str]:
    """Re-run at a 1000× looser tolerance and say how the two runs part.

    Exponentially (chaos: trust the details up to where they part), steadily in phase (a timing
    drift, told as timing), or not at all; see mechanics/divergence.py. A run cut by a stop is
    compared over the samples both runs share.
    """
    # 1000× looser, capped at 1e-3; a run already at or past the cap is compared with one 10×
    # looser (at rtol 1e-3 the capped re-run was the run itself: 'at rtol 0.001 and 0.001')
    rtol, atol = min(req.rtol * 1e3, 1e-3), min(req.atol * 1e3, 1e-3)
    if rtol <= req.rtol:
        rtol, atol = min(req.rtol * 10, 1.0), min(max(req.atol, atol) * 10, 1.0)
    loose = _run(c, params, y0, t_eval, req, rtol, atol)
    shared = min(len(loose.t), len(run.t) - (1 if run.status == "stopped" else 0))
    if loose.status != "ok" and len(loose.t) < len(run.t) or shared < 3:
        return []
    if not worth_classifying(c.n, run.y[:shared], loose.y[:shared]):
        return []
    verdict = compare_runs(
        c, params, run.t[:shared], run.y[:shared], loose.y[:shared], (req.rtol, rtol)
    )
    return [verdict.message] if verdict.message else []


def simulate(
    scene_id: str | None = None, scene: dict | None = None, request: SimulationRequest | None = None
) -> dict[str, Any]:
    """Simulate a built-in scene (by id) or a spec; raises SpecError naming bad fields.

    A state on the other side of a spring's anchor than the derivation's is run on the variant
    derived for that side (ℓ = −p instead of p), so V = ½k(|d| − ℓ₀)² holds wherever a run starts.
    """
    req = request or SimulationRequest()
    branches: dict[int, int] = {}
    for _ in range(MAX_BRANCH_FLIPS):
        key = tuple(sorted(branches.items()))
        c = compiled_scene(scene_id, key) if scene_id is not None else compiled_spec(scene, key)
        try:
            return simulate_compiled(c, req)
        except _OtherBranch as other:
            branches = {**c.derivation.model.branches, **other.flips}
    raise SpecError([{"field": "initial", "message": "no derivation matches this state"}])
