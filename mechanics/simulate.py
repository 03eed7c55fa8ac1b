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
from scipy.integrate import cumulative_simpson

from mechanics.integrators import METHODS, integrate
from mechanics.native import NativeUnavailable
from mechanics.numeric import (
    CompiledScene,
    compiled_scene,
    compiled_spec,
    constraint_force_functions,
    evaluate,
)
from mechanics.spec import SpecError

MAX_T_END = 1000.0
MAX_SAMPLES = 20_001
MAX_FPS = 240
MAX_WALL_TIME = 10.0
MAX_FIXED_STEPS = 2_000_000
#: Above this relative energy error the run carries a warning.
ENERGY_WARNING = 1e-3


@dataclass
class SimulationRequest:
    parameters: dict[str, float] = field(default_factory=dict)
    initial: dict[str, float] = field(default_factory=dict)
    t_end: float = 10.0
    fps: float = 60.0
    method: str = "DOP853"
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
        ("fps", math.isfinite(req.fps) and 0 < req.fps <= MAX_FPS, f"must be in (0, {MAX_FPS}]"),
        ("method", req.method in METHODS, f"unknown method; one of {', '.join(METHODS)}"),
        ("rtol", math.isfinite(req.rtol) and 1e-14 <= req.rtol <= 1e-1, "must be in [1e-14, 0.1]"),
        ("atol", math.isfinite(req.atol) and 1e-16 <= req.atol <= 1, "must be in [1e-16, 1]"),
    ]
    if req.t_end * req.fps + 1 > MAX_SAMPLES:
        checks.append(("fps", False, f"t_end × fps gives more than {MAX_SAMPLES} samples"))
    if req.method in METHODS and METHODS[req.method].kind == "fixed":
        ok = req.dt is not None and math.isfinite(req.dt) and req.dt > 0
        checks.append(("dt", ok, "a fixed-step method needs a step dt > 0"))
        if ok and req.t_end / req.dt > MAX_FIXED_STEPS:
            checks.append(("dt", False, f"t_end / dt exceeds {MAX_FIXED_STEPS} steps"))
    errors += [{"field": f, "message": m} for f, ok, m in checks if not ok]
    if errors:
        raise SpecError(errors)
    values = {**spec.parameters, **req.parameters}
    init = {**spec.initial, **req.initial}
    y0 = [init.get(q, 0.0) for q in c.coordinates] + [
        init.get(f"{q}_dot", 0.0) for q in c.coordinates
    ]
    return [values[k] for k in c.parameters], np.array([*y0, 0.0])


def _run(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    t_eval: np.ndarray,
    req: SimulationRequest,
    rtol: float,
    atol: float,
):
    compiled, why = None, ""
    if req.method == "dop853_c":
        try:
            compiled = c.native_rhs(params)
        except NativeUnavailable as exc:
            why = str(exc)  # the C loop calls the Python right-hand side back (or scipy runs it)
    run = integrate(
        c.rhs(params),
        y0,
        t_eval,
        method=req.method,
        rtol=rtol,
        atol=atol,
        dt=req.dt,
        max_wall_time=MAX_WALL_TIME,
        second_order=c.n,
        native=compiled,
    )
    if why and not run.note:
        run.note = f"The equations could not be compiled to C ({why}): the C loop called Python."
    return run


def simulate_compiled(c: CompiledScene, req: SimulationRequest) -> dict[str, Any]:
    params, y0 = check_request(c, req)
    n_samples = int(math.floor(req.t_end * req.fps + 1e-9)) + 1
    t_eval = np.linspace(0.0, (n_samples - 1) / req.fps, n_samples)
    run = _run(c, params, y0, t_eval, req, req.rtol, req.atol)
    warnings: list[str] = [run.note] if run.note else []
    if run.status != "ok":
        warnings.append(f"The run stopped early: {run.message}. The trajectory is partial.")
        if "step" in run.message.lower() or "budget" in run.message.lower():
            if not METHODS[req.method].implicit:
                warnings.append("This looks stiff for an explicit method: try Radau or BDF.")
    t, y = run.t, run.y
    n = c.n
    q, qd, w_nc = y[:, :n].T, y[:, n : 2 * n].T, y[:, 2 * n]
    T, V = evaluate(c.energy, t, q, qd, params)
    E = T + V
    stats: dict[str, Any] = {
        "method": req.method,
        "steps": run.nsteps,
        "rhs_evaluations": run.nfev,
        "jacobian_evaluations": run.njev,
        "wall_time": run.wall_time,
        "samples": len(t),
        "status": run.status,
    }
    scale = max(float(np.max(np.abs(T))) if len(T) else 0.0, 1e-300)
    conserved = {x["name"] for x in c.derivation.work.conserved}
    if "energy" in conserved:
        stats["energy_error"] = float(np.max(np.abs(E - E[0]))) / scale
    elif c.jacobi is not None:
        (h,) = evaluate(c.jacobi, t, q, qd, params)
        stats["jacobi_error"] = float(np.max(np.abs(h - h[0]))) / scale
    else:
        stats["energy_balance_error"] = float(np.max(np.abs(E - E[0] - w_nc))) / scale
    drift = {}
    for name, fn in c.momenta.items():
        (p,) = evaluate(fn, t, q, qd, params)
        drift[name] = float(np.max(np.abs(p - p[0]))) / max(float(np.max(np.abs(p))), 1e-300)
    stats["momentum_drift"] = drift
    worst = max((v for k, v in stats.items() if k.endswith("_error")), default=0.0)
    if worst > ENERGY_WARNING and scale > 1e-300:
        warnings.append(
            f"The conserved quantity drifted by {worst:.1e} of the kinetic energy: "
            "tighten the tolerance or the step, or pick a higher-order method."
        )
    warnings += _singularity_warnings(c, t, q, qd, params)
    if req.check_sensitivity and METHODS[req.method].kind == "adaptive" and run.status == "ok":
        warnings += _sensitivity(c, params, y0, t_eval, req, run)
    positions = {
        name: dict(zip("xyz", evaluate(fn, t, q, qd, params), strict=True))
        for name, fn in c.places.items()
    }
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
        "energy": {"T": T.tolist(), "V": V.tolist(), "E": E.tolist(), "W_nc": w_nc.tolist()},
        "positions": {k: {a: v.tolist() for a, v in xyz.items()} for k, xyz in positions.items()},
        "frames": {k: v.tolist() for k, v in frames.items()},
        "stats": stats,
        "warnings": warnings,
    }


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


def _constraint_forces(c, t, q, qd, params, warnings) -> dict[str, dict[str, list[float]]]:
    """R = m a − ΣF along the run; a rod's tension, and where a string would go slack."""
    out = {}
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
    """Re-run at a 1000× looser tolerance; a large difference marks a sensitive motion."""
    loose = _run(c, params, y0, t_eval, req, min(req.rtol * 1e3, 1e-3), min(req.atol * 1e3, 1e-3))
    if loose.status != "ok" or len(loose.t) != len(run.t):
        return []
    n = c.n
    diff = np.abs(loose.y[:, :n] - run.y[:, :n])
    span = np.max(np.abs(run.y[:, :n]), axis=0) + 1e-12
    rel = np.max(diff / span, axis=0)
    worst = int(np.argmax(rel))
    if rel[worst] < 1e-2:
        return []
    i = int(np.argmax(diff[:, worst] / span[worst] > 1e-2))
    return [
        f"The motion is sensitive to small errors: at rtol {req.rtol:g} and "
        f"{min(req.rtol * 1e3, 1e-3):g} the trajectories of {c.coordinates[worst]} part "
        f"from t ≈ {run.t[i]:.3g} s (difference {diff[-1, worst]:.3g} at the end). Trust it "
        "only up to there, or tighten the tolerance and compare again."
    ]


def simulate(
    scene_id: str | None = None, scene: dict | None = None, request: SimulationRequest | None = None
) -> dict[str, Any]:
    """Simulate a built-in scene (by id) or a spec; raises SpecError naming bad fields."""
    c = compiled_scene(scene_id) if scene_id is not None else compiled_spec(scene)
    return simulate_compiled(c, request or SimulationRequest())
