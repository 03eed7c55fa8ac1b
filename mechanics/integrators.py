"""A registry of ODE integrators behind one interface, like scipy's ``solve_ivp(method=...)``.

The fixed-step methods are there to teach the trade (order, symplecticity, cost per step); the
adaptive ones are scipy's. Every run samples the solution at the requested times (dense output,
not the raw steps), counts what it cost, and stops — returning what it has, with the reason —
when the state stops being finite or a budget runs out. It never hangs.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import integrate as si


@dataclass(frozen=True)
class MethodInfo:
    name: str
    label: str
    kind: str  # "fixed" | "adaptive"
    order: int
    symplectic: bool
    implicit: bool
    description: str


METHODS: dict[str, MethodInfo] = {
    m.name: m
    for m in (
        MethodInfo(
            "euler",
            "Explicit Euler",
            "fixed",
            1,
            False,
            False,
            "One slope per step. Cheap and simple; energy grows steadily — shows why "
            "nobody integrates orbits with it.",
        ),
        MethodInfo(
            "symplectic_euler",
            "Semi-implicit (symplectic) Euler",
            "fixed",
            1,
            True,
            False,
            "Update the velocity first, then the position with the new velocity. "
            "First order, but the energy error stays bounded over long runs.",
        ),
        MethodInfo(
            "rk4",
            "Classical Runge–Kutta (RK4)",
            "fixed",
            4,
            False,
            False,
            "Four slopes per step; very accurate per step, but the energy drifts slowly "
            "in long conservative runs.",
        ),
        MethodInfo(
            "implicit_midpoint",
            "Implicit midpoint",
            "fixed",
            2,
            True,
            True,
            "Symplectic and time-reversible: conserves quadratic invariants exactly and "
            "keeps the energy error bounded; each step solves a small nonlinear system.",
        ),
        MethodInfo(
            "RK45",
            "Dormand–Prince 5(4) (scipy RK45)",
            "adaptive",
            5,
            False,
            False,
            "The general-purpose default of scipy: adapts the step to rtol/atol.",
        ),
        MethodInfo(
            "DOP853",
            "Dormand–Prince 8(5,3) (scipy DOP853)",
            "adaptive",
            8,
            False,
            False,
            "High order: the cheapest way to very tight tolerances on smooth problems.",
        ),
        MethodInfo(
            "dop853_fortran",
            "DOP853, Hairer's Fortran code (scipy ode)",
            "adaptive",
            8,
            False,
            False,
            "The same method as DOP853, stepped in compiled Fortran: several times less "
            "overhead per step, for fast tight-tolerance runs.",
        ),
        MethodInfo(
            "Radau",
            "Radau IIA (scipy Radau)",
            "adaptive",
            5,
            False,
            True,
            "Implicit, L-stable: for stiff systems (very stiff springs) where explicit "
            "methods need absurdly small steps.",
        ),
        MethodInfo(
            "BDF",
            "Backward differentiation (scipy BDF)",
            "adaptive",
            5,
            False,
            True,
            "Implicit multistep of variable order 1–5: for stiff systems.",
        ),
        MethodInfo(
            "LSODA",
            "LSODA (scipy)",
            "adaptive",
            12,
            False,
            True,
            "Switches between Adams (non-stiff) and BDF (stiff) automatically.",
        ),
    )
}

_SCIPY = {"RK45": si.RK45, "DOP853": si.DOP853, "Radau": si.Radau, "BDF": si.BDF, "LSODA": si.LSODA}


@dataclass
class Trajectory:
    t: np.ndarray
    y: np.ndarray  # (len(t), n_state)
    status: str  # "ok" | "stopped"
    message: str
    nfev: int
    nsteps: int
    njev: int
    wall_time: float


class _Counted:
    """Wraps the RHS to count calls and enforce the wall-time budget from inside the solver."""

    def __init__(self, rhs: Callable, deadline: float) -> None:
        self.rhs, self.deadline, self.calls = rhs, deadline, 0

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        self.calls += 1
        if self.calls % 256 == 0 and time.perf_counter() > self.deadline:
            raise _OutOfTime
        return self.rhs(t, y)


class _OutOfTime(Exception):
    pass


def integrate(
    rhs: Callable[[float, np.ndarray], np.ndarray],
    y0: np.ndarray,
    t_eval: np.ndarray,
    *,
    method: str = "DOP853",
    rtol: float = 1e-9,
    atol: float = 1e-9,
    dt: float | None = None,
    max_wall_time: float = 10.0,
    max_steps: int = 5_000_000,
    second_order: int | None = None,
) -> Trajectory:
    """Integrate dy/dt = rhs(t, y) and sample at t_eval (increasing, starting at t0).

    `second_order` = n says y = [q (n), v (n), extra...] with dq/dt = v: the symplectic methods
    need that split. Extra states (e.g. the work of non-conservative forces) follow along.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method '{method}'; one of {', '.join(METHODS)}")
    start = time.perf_counter()
    f = _Counted(rhs, start + max_wall_time)
    t_eval = np.asarray(t_eval, dtype=float)
    y0 = np.asarray(y0, dtype=float)
    if len(t_eval) == 1:
        return Trajectory(t_eval, y0[None, :].copy(), "ok", "", 0, 0, 0, 0.0)
    if METHODS[method].kind == "fixed":
        if dt is None or not dt > 0 or not math.isfinite(dt):
            raise ValueError(f"{method} is a fixed-step method: give a step dt > 0")
        out, status, message, nsteps = _fixed(method, f, y0, t_eval, dt, max_steps, second_order)
        njev = 0
    elif method == "dop853_fortran":
        out, status, message, nsteps = _fortran(f, y0, t_eval, rtol, atol, max_steps)
        njev = 0
    else:
        out, status, message, nsteps, njev = _adaptive(method, f, y0, t_eval, rtol, atol, max_steps)
    ys = np.array(out) if out else np.empty((0, len(y0)))
    return Trajectory(
        t_eval[: len(out)], ys, status, message, f.calls, nsteps, njev, time.perf_counter() - start
    )


def _adaptive(method, f, y0, t_eval, rtol, atol, max_steps):
    """Step scipy's solver by hand so a run can stop with what it has, and sample densely."""
    out = [y0.copy()]
    k = 1
    try:
        solver = _SCIPY[method](f, t_eval[0], y0, t_eval[-1], rtol=rtol, atol=atol)
        nsteps = 0
        while k < len(t_eval):
            message = solver.step()
            if solver.status == "failed":
                return out, "stopped", f"{message} at t = {solver.t:.6g} s", nsteps, solver.njev
            nsteps += 1
            if nsteps > max_steps:
                return (
                    out,
                    "stopped",
                    f"step budget ({max_steps}) exhausted at t = {solver.t:.6g} s",
                    nsteps,
                    solver.njev,
                )
            if not np.all(np.isfinite(solver.y)):
                return (
                    out,
                    "stopped",
                    f"state became non-finite at t = {solver.t:.6g} s",
                    nsteps,
                    solver.njev,
                )
            if k < len(t_eval) and t_eval[k] <= solver.t:
                dense = solver.dense_output()
                while k < len(t_eval) and t_eval[k] <= solver.t:
                    out.append(dense(t_eval[k]))
                    k += 1
        return out, "ok", "", nsteps, solver.njev
    except _OutOfTime:
        return (
            out,
            "stopped",
            f"wall-time budget exhausted at t = {t_eval[k - 1]:.6g} s",
            nsteps,
            getattr(solver, "njev", 0),
        )
    except (FloatingPointError, OverflowError, ZeroDivisionError, ValueError) as exc:
        return out, "stopped", f"{type(exc).__name__} near t = {t_eval[k - 1]:.6g} s", 0, 0


def _fortran(f, y0, t_eval, rtol, atol, max_steps):
    """scipy's `ode('dop853')`: the Fortran integrator lands on each output time in turn."""
    solver = si.ode(f).set_integrator("dop853", rtol=rtol, atol=atol, nsteps=max_steps)
    solver.set_initial_value(y0, t_eval[0])
    out = [y0.copy()]
    nsteps = 0
    try:
        for t1 in t_eval[1:]:
            y = solver.integrate(t1)
            nsteps += int(solver._integrator.iwork[17])  # NSTEP of this call: IWORK(18)
            if not solver.successful():
                return out, "stopped", f"dop853 failed near t = {solver.t:.6g} s", nsteps
            if not np.all(np.isfinite(y)):
                return out, "stopped", f"state became non-finite at t ≈ {t1:.6g} s", nsteps
            out.append(y.copy())
        return out, "ok", "", nsteps
    except _OutOfTime:
        at = t_eval[len(out) - 1]
        return out, "stopped", f"wall-time budget exhausted at t = {at:.6g} s", nsteps


def _fixed(method, f, y0, t_eval, dt, max_steps, n):
    """Land exactly on every output time: each interval gets ⌈Δt/dt⌉ equal steps of ≤ dt."""
    n = len(y0) // 2 if n is None else n
    step = _STEPPERS[method]
    y = y0.copy()
    out = [y.copy()]
    nsteps = 0
    try:
        for k in range(1, len(t_eval)):
            t0, t1 = t_eval[k - 1], t_eval[k]
            m = max(1, math.ceil((t1 - t0) / dt - 1e-9))
            h = (t1 - t0) / m
            for i in range(m):
                y = step(f, t0 + i * h, y, h, n)
                nsteps += 1
            if not np.all(np.isfinite(y)):
                return out, "stopped", f"state became non-finite at t ≈ {t1:.6g} s", nsteps
            if nsteps > max_steps:
                return (
                    out,
                    "stopped",
                    f"step budget ({max_steps}) exhausted at t = {t1:.6g} s",
                    nsteps,
                )
            out.append(y.copy())
        return out, "ok", "", nsteps
    except _OutOfTime:
        return (
            out,
            "stopped",
            f"wall-time budget exhausted at t = {t_eval[len(out) - 1]:.6g} s",
            nsteps,
        )
    except (FloatingPointError, OverflowError, ZeroDivisionError) as exc:
        return out, "stopped", f"{type(exc).__name__} near t = {t_eval[len(out) - 1]:.6g} s", nsteps


def _euler(f, t, y, h, n):
    return y + h * f(t, y)


def _symplectic_euler(f, t, y, h, n):
    """v ← v + h a(q, v); q ← q + h v_new; extra states by the same explicit slope."""
    d = f(t, y)
    new = y + h * d
    new[:n] = y[:n] + h * new[n : 2 * n]
    return new


def _rk4(f, t, y, h, n):
    k1 = f(t, y)
    k2 = f(t + h / 2, y + h / 2 * k1)
    k3 = f(t + h / 2, y + h / 2 * k2)
    k4 = f(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def _implicit_midpoint(f, t, y, h, n):
    """y1 = y + h f(t + h/2, (y + y1)/2), by fixed point, then Newton if that stalls."""
    y1 = y + h * f(t, y)
    for _ in range(50):
        nxt = y + h * f(t + h / 2, (y + y1) / 2)
        if np.max(np.abs(nxt - y1)) <= 1e-14 * (1 + np.max(np.abs(nxt))):
            return nxt
        y1 = nxt
    for _ in range(20):  # Newton on g(z) = z - y - h f(t + h/2, (y + z)/2)
        mid = (y + y1) / 2
        g = y1 - y - h * f(t + h / 2, mid)
        eps = 1e-8
        J = np.eye(len(y))
        base = f(t + h / 2, mid)
        for j in range(len(y)):
            dm = mid.copy()
            dm[j] += eps
            J[:, j] -= h / 2 * (f(t + h / 2, dm) - base) / eps
        delta = np.linalg.solve(J, -g)
        y1 = y1 + delta
        if np.max(np.abs(delta)) <= 1e-14 * (1 + np.max(np.abs(y1))):
            break
    return y1


_STEPPERS = {
    "euler": _euler,
    "symplectic_euler": _symplectic_euler,
    "rk4": _rk4,
    "implicit_midpoint": _implicit_midpoint,
}
