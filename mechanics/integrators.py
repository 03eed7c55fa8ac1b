"""A registry of ODE integrators behind one interface, like scipy's ``solve_ivp(method=...)``.

Students trade speed for accuracy: the fixed-step methods are here to teach that trade (order,
symplecticity, cost per step), the adaptive ones are scipy's steppers. Every run samples the
solution only at the requested output times (dense output, not the raw steps), counts what it
cost, and never hangs: when the state stops being finite, the solver gives up, or a budget (wall
time, steps) runs out, it stops and returns the partial trajectory with the reason.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mechanics import native as native_code
from mechanics.native import NativeRhs

Rhs = Callable[[float, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class MethodInfo:
    """What the app shows about a method, so students can pick one knowingly."""

    name: str  # registry key, e.g. "rk4"
    label: str
    kind: str  # "fixed" | "adaptive"
    order: int
    #: symplectic in (q, q̇) for a constant mass matrix only: the methods step q̇, not p = M q̇
    symplectic: bool
    implicit: bool
    description: str


# fmt: off
METHODS: dict[str, MethodInfo] = {
    m.name: m
    for m in (
        MethodInfo("euler", "Explicit Euler", "fixed", 1, False, False,
            "One slope per step. Cheap and simple, but the energy of an oscillator grows "
            "every step: the textbook example of what not to integrate orbits with."),
        MethodInfo("symplectic_euler", "Semi-implicit (symplectic) Euler", "fixed", 1, True, False,
            "Update the velocity first, then the position with the new velocity. First order; "
            "symplectic only when the mass matrix is constant (Cartesian-like coordinates: "
            "springs, a simple pendulum), where its energy error stays bounded over very long "
            "runs. With a mass matrix that depends on the coordinates (double pendulum, cart "
            "pendulum) it steps q̇, not the momenta, and its energy drifts."),
        MethodInfo("rk4", "Classical Runge–Kutta (RK4)", "fixed", 4, False, False,
            "Four slopes per step: very accurate per step, but in long conservative runs the "
            "energy drifts slowly one way."),
        MethodInfo("implicit_midpoint", "Implicit midpoint", "fixed", 2, True, True,
            "Time-reversible, and symplectic when the mass matrix is constant (Cartesian-like "
            "coordinates), where it keeps the energy error bounded; it steps (q, q̇), not the "
            "momenta, so with a mass matrix that depends on the coordinates it is not "
            "symplectic in general. Each step solves a small nonlinear system."),
        MethodInfo("RK45", "Dormand–Prince 5(4) (scipy RK45)", "adaptive", 5, False, False,
            "scipy's general-purpose default: adapts the step to meet rtol/atol."),
        MethodInfo("DOP853", "Dormand–Prince 8(5,3) (scipy DOP853)", "adaptive", 8, False, False,
            "High order: the cheapest way to very tight tolerances on smooth problems."),
        MethodInfo("dop853_fortran", "DOP853, Hairer's Fortran code (scipy ode)", "adaptive", 8,
            False, False,
            "The same method as DOP853 stepped in compiled Fortran: less overhead per step, "
            "for fast tight-tolerance runs."),
        MethodInfo("dop853_c", "DOP853, compiled to C for this scene", "adaptive", 8, False,
            False,
            "The same steps as scipy's DOP853, with the scene's equations generated as C and "
            "the stepping loop in C: the fastest way to tight tolerances (a few ms per run)."),
        MethodInfo("Radau", "Radau IIA (scipy Radau)", "adaptive", 5, False, True,
            "Implicit and L-stable: for stiff systems (very stiff springs) where explicit "
            "methods need absurdly small steps."),
        MethodInfo("BDF", "Backward differentiation (scipy BDF)", "adaptive", 5, False, True,
            "Implicit multistep of variable order 1–5 (5 is the maximum): for stiff systems."),
        MethodInfo("LSODA", "LSODA (scipy)", "adaptive", 12, False, True,
            "Switches automatically between Adams (non-stiff, order up to 12) and BDF "
            "(stiff, order up to 5)."),
    )
}
# fmt: on


def _scipy_solver(name: str) -> type:
    """scipy's stepper class by name, imported on first use: the registry above is read by the
    API's schemas at startup, and scipy.integrate costs 0.4 s to import."""
    from scipy import integrate as si

    return getattr(si, name)


@dataclass
class Trajectory:
    """The samples reached (a prefix of t_eval) and what they cost."""

    t: np.ndarray  # the requested output times actually reached
    y: np.ndarray  # (len(t), n_state)
    status: str  # "ok" | "stopped"
    message: str  # why it stopped ("" when ok)
    nfev: int  # right-hand-side evaluations, Jacobian differences and implicit solves included
    nsteps: int  # accepted steps
    njev: int  # Jacobian evaluations (0 when the method has none)
    wall_time: float  # seconds
    note: str = ""  # how the method ran, when not as named (e.g. no C compiler: scipy's DOP853)
    t_reached: float = math.nan  # how far the stepping got (past the last sample when stopped)
    #: A fixed-step method's largest step (NaN for adaptive ones): the step actually taken, which
    #: is dt itself when the output times are whole multiples of dt apart.
    step: float = math.nan
    #: The last state the stepping reached (at t_reached; None where the C or Fortran loop ran):
    #: when a run stops, how large the state had grown tells a blow-up from stiffness.
    y_reached: np.ndarray | None = None
    #: The method that ran: the one asked for, or "DOP853" where ``dop853_c`` could not (``note``
    #: says why). The answer's stats name it, so nobody reads scipy's timings as the C loop's.
    method: str = ""

    def __post_init__(self) -> None:
        # Counters reach the JSON of a response: plain Python numbers, whatever counted them
        # (LSODA's njev is a numpy int32, the C loop's counts come through ctypes).
        self.nfev, self.nsteps, self.njev = int(self.nfev), int(self.nsteps), int(self.njev)
        self.wall_time = float(self.wall_time)


class _Stop(Exception):
    """Ends a run early; the message says why and when."""


#: What a right-hand side raises because of the motion (math.exp overflow, a singular M), not
#: because of a bug: the run stops and says so instead of raising.
_PHYSICAL = (ArithmeticError, np.linalg.LinAlgError)


def _physical_stop(exc: BaseException, t: float) -> str:
    """What happened, in words (it reaches students as a warning): not "OverflowError (34,
    'Numerical result out of range')"."""
    if isinstance(exc, OverflowError):
        return (
            f"a step overflowed near t = {t:.6g} s: a number in the equations grew past the "
            "range of a double (about 1e308)"
        )
    if isinstance(exc, ZeroDivisionError):
        return f"the equations divided by zero near t = {t:.6g} s"
    if isinstance(exc, np.linalg.LinAlgError):
        return f"the mass matrix became singular near t = {t:.6g} s"
    return f"an arithmetic error near t = {t:.6g} s ({exc})"


def _beyond_doubles(exc: BaseException) -> bool:
    """Did numpy/scipy refuse numbers past the range of a double (an implicit method's Jacobian
    of finite differences overflows for m = 1e-215 while q̈ stays finite)?"""
    text = str(exc)
    return isinstance(exc, np.linalg.LinAlgError) or "infs or NaNs" in text


def _finite(v: np.ndarray) -> bool:
    """All entries finite? A sum of Python floats is ten times cheaper than np.isfinite on the
    few numbers of a state, and it runs on every RHS call (NaN and ±inf propagate into it).
    A complex right-hand side never gets here: `_Counted` stops the run on it."""
    return math.isfinite(sum(v.tolist()))


class _Counted:
    """Wraps the RHS: counts calls, enforces the wall-time deadline from inside the solver, and
    remembers where the RHS first returned a non-finite value (so a solver failure can be
    blamed on it). With ``fortran`` set it never raises — an exception through scipy's Fortran
    callback kills the process — but stores the failure and returns zeros until the step ends.
    """

    def __init__(self, rhs: Rhs, budget: float, start: float) -> None:
        self.rhs, self.budget, self.deadline = rhs, budget, start + budget
        self.calls, self.t = 0, math.nan
        self.watch = self.fortran = False
        self.bad_t: float | None = None
        self.failure: BaseException | None = None
        self.stop_watch: Callable[[float, np.ndarray], bool] | None = None

    def watched(self, t: float, y: np.ndarray) -> bool:
        """Has a stop condition been reached at this step's end?"""
        return self.stop_watch is not None and bool(self.stop_watch(t, y))

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        self.calls += 1
        self.t = t
        if self.failure is not None:
            return np.zeros_like(y)
        try:
            if time.perf_counter() > self.deadline:
                raise _Stop(f"wall-time budget of {self.budget:g} s exhausted at t = {t:.6g} s")
            d = self.rhs(t, y)
            if np.iscomplexobj(d):  # x**(1/3) of a negative x: numbers cast to real would lie
                raise _Stop(
                    f"the state left the domain of the scene's functions at t = {t:.6g} s (a "
                    "root or a power of a negative number): the model ends there"
                )
        except Exception as exc:
            if not self.fortran:
                raise
            self.failure = exc
            return np.zeros_like(y)
        if self.watch and not _finite(d):
            self.bad_t = t if self.bad_t is None else self.bad_t
            if self.fortran:
                self.failure = _Stop(f"the right-hand side became non-finite at t = {t:.6g} s")
                return np.zeros_like(y)
        return d


class _Run:
    """The samples and counters so far: they survive a `_Stop` raised anywhere in a run."""

    def __init__(self, y0: np.ndarray) -> None:
        self.out, self.nsteps, self.njev = [y0.copy()], 0, 0
        self.step = math.nan  # the largest fixed step taken
        self.last: np.ndarray | None = None  # the last state stepped to (Python paths)


def integrate(
    rhs: Rhs,
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
    native: NativeRhs | None = None,
    watch: Callable[[float, np.ndarray], bool] | None = None,
) -> Trajectory:
    """Integrate dy/dt = rhs(t, y) from y0 and sample it at t_eval (increasing, from t0).

    Fixed-step methods need ``dt``; they land exactly on every output time (each interval gets
    ⌈Δt/dt⌉ equal steps of size ≤ dt), so every sample is a genuine step of the method, never
    an interpolation. Output times whole multiples of dt apart keep the step dt itself (what
    `mechanics.simulate` asks for); ``Trajectory.step`` says the largest step taken. Adaptive
    methods use ``rtol``/``atol`` and sample by the solver's own dense output.
    ``second_order`` = n says y = [q (n), v (n), extra...] with dq/dt = v; symplectic Euler
    needs that split (None means y = [q, v] in halves). Extra states (e.g.
    the work of non-conservative forces) ride along with the method's update.

    ``dop853_c`` steps in C: with ``native`` (the scene's generated C right-hand side, the same
    function as ``rhs``) no Python runs per step; without it ``rhs`` is called back from C.
    Where no C compiler is available it runs scipy's DOP853 instead (the same steps) and says
    so in ``note``.

    ``watch(t, y)`` is asked after every step the Python paths take; True ends the run there
    (status "stopped"): the model stops holding (a stop condition), and stepping on would only
    chatter at a discontinuity. The caller locates the exact moment. The C loop is not watched.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; valid methods: {', '.join(METHODS)}")
    t_eval = np.asarray(t_eval, dtype=float)
    y0 = np.asarray(y0, dtype=float)
    if t_eval.ndim != 1 or len(t_eval) == 0 or not np.all(np.isfinite(t_eval)):
        raise ValueError("t_eval must be a non-empty 1-D array of finite times")
    if np.any(np.diff(t_eval) <= 0):
        raise ValueError("t_eval must be strictly increasing")
    if y0.ndim != 1 or not np.all(np.isfinite(y0)):
        raise ValueError("y0 must be a 1-D array of finite numbers")
    n = len(y0) // 2 if second_order is None else second_order
    if not 0 <= 2 * n <= len(y0) or (method == "symplectic_euler" and n == 0):
        raise ValueError(f"second_order={second_order} does not split a state of {len(y0)}")
    if method == "symplectic_euler" and second_order is None and len(y0) % 2:
        raise ValueError("symplectic_euler needs y = [q, v]: give second_order=n for this state")
    if METHODS[method].kind == "fixed" and (dt is None or not (math.isfinite(dt) and dt > 0)):
        raise ValueError(f"{method} is a fixed-step method: give a finite step dt > 0")
    start = time.perf_counter()
    if len(t_eval) == 1:
        return Trajectory(t_eval.copy(), y0[None, :].copy(), "ok", "", 0, 0, 0, 0.0, method=method)

    f, run = _Counted(rhs, max_wall_time, start), _Run(y0)
    f.stop_watch = watch
    status, message, note = "ok", "", ""
    if method == "dop853_c":
        why = native_code.available()
        if why is None:
            run = _compiled(native or f, y0, t_eval, rtol, atol, max_steps, max_wall_time, start)
            run.method = "dop853_c"
            return run
        method, note = "DOP853", f"ran scipy's DOP853 (the same steps, slower): {why}"
    try:
        with np.errstate(all="ignore"):  # non-finite values are detected and reported, not warned
            if METHODS[method].kind == "fixed":
                _fixed(run, _STEPPERS[method], f, t_eval, dt, max_steps, n)
            elif method == "dop853_fortran":
                _fortran(run, f, y0, t_eval, rtol, atol, max_steps)
            else:
                _adaptive(run, _scipy_solver(method), f, y0, t_eval, rtol, atol, max_steps)
    except _Stop as stop:
        status, message = "stopped", str(stop)
    except _PHYSICAL as exc:
        status, message = "stopped", _physical_stop(exc, f.t)
    return Trajectory(
        t_eval[: len(run.out)].copy(),
        np.array(run.out),
        status,
        message,
        f.calls,
        run.nsteps,
        run.njev,
        time.perf_counter() - start,
        note,
        f.t if status != "ok" else float(t_eval[-1]),
        run.step,
        run.last,
        method,
    )


_NATIVE_STOPS = {
    native_code.STEP_BUDGET: "step budget ({max_steps}) exhausted at t = {t:.6g} s",
    native_code.TOO_SMALL: "solver failed at t = {t:.6g} s: the step size became too small",
    native_code.NONFINITE: "the right-hand side became non-finite at t = {bad:.6g} s",
    native_code.WALL_TIME: "wall-time budget of {budget:g} s exhausted at t = {t:.6g} s",
    native_code.NO_MEMORY: "out of memory at t = {t:.6g} s",
}


def _compiled(rhs, y0, t_eval, rtol, atol, max_steps, budget, start) -> Trajectory:
    """The C loop: same algorithm as scipy's DOP853; the statuses map onto the same messages."""
    r = native_code.dop853(
        rhs, y0, t_eval, rtol=rtol, atol=atol, max_steps=max_steps, max_seconds=budget
    )
    status, message = "ok", ""
    if r.status == native_code.RHS_ERROR:
        status = "stopped"
        if isinstance(r.error, _Stop):
            message = str(r.error)
        elif r.error is not None and not isinstance(r.error, _PHYSICAL):
            raise r.error  # a bug in the caller's function, not a property of the motion
        elif r.error is not None:
            message = _physical_stop(r.error, r.t_reached)
        elif r.rhs_code == native_code.RHS_SINGULAR:
            message = f"the mass matrix became singular at t = {r.t_reached:.6g} s"
        else:
            message = f"the right-hand side failed (code {r.rhs_code}) at t = {r.t_reached:.6g} s"
    elif r.status != native_code.OK:
        status = "stopped"
        message = _NATIVE_STOPS[r.status].format(
            max_steps=max_steps, t=r.t_reached, bad=r.t_bad, budget=budget
        )
    return Trajectory(
        t_eval[: len(r.y)].copy(),
        r.y,
        status,
        message,
        r.nfev,
        r.nsteps,
        0,
        time.perf_counter() - start,
        t_reached=r.t_reached,
    )


def _fixed(run: _Run, step, f: _Counted, t_eval, dt, max_steps, n) -> None:
    """Exact landing: each output interval gets ⌈Δt/dt⌉ equal steps of size ≤ dt."""
    y = run.out[0]
    for k in range(1, len(t_eval)):
        t0, t1 = t_eval[k - 1], t_eval[k]
        m = max(1, math.ceil((t1 - t0) / dt - 1e-9))  # tolerate Δt/dt = 10.000000000002
        h = (t1 - t0) / m
        run.step = h if math.isnan(run.step) else max(run.step, h)
        for i in range(m):
            if run.nsteps >= max_steps:
                raise _Stop(f"step budget ({max_steps}) exhausted at t = {t0 + i * h:.6g} s")
            y = step(f, t0 + i * h, y, h, n)
            run.nsteps += 1
            run.last = y
            if not _finite(y):
                raise _Stop(f"state became non-finite at t = {t0 + (i + 1) * h:.6g} s")
            if f.watched(t0 + (i + 1) * h, y):
                raise _Stop(f"a stop condition was reached near t = {t0 + (i + 1) * h:.6g} s")
        run.out.append(y)


def _adaptive(run: _Run, cls, f: _Counted, y0, t_eval, rtol, atol, max_steps) -> None:
    """Step scipy's solver class by hand: partial results, exact stats, budgets per step.

    (solve_ivp would only report at the end.) After each accepted step, the output times inside
    it are sampled from the step's dense-output interpolant.
    """
    f.watch = True
    solver = cls(f, t_eval[0], y0, t_eval[-1], rtol=rtol, atol=atol)
    k = 1
    while k < len(t_eval):
        if run.nsteps >= max_steps:
            raise _Stop(f"step budget ({max_steps}) exhausted at t = {solver.t:.6g} s")
        f.bad_t = None
        t_before = solver.t
        try:
            message = solver.step()
        except (ValueError, np.linalg.LinAlgError) as exc:  # e.g. the LU of a NaN Jacobian
            if f.bad_t is None and not _beyond_doubles(exc):
                raise
            solver.status = "failed"
            message = "the Jacobian is not finite (its entries overflow double precision)"
        run.njev = int(solver.njev)  # LSODA counts in a numpy int32
        run.last = solver.y
        if solver.t == t_before and solver.status == "running":
            # LSODA at a blow-up reports "running" steps of size 0 (t stuck, y drifting) until a
            # budget runs out: no progress is a failure, blamed on a non-finite RHS if there was one
            solver.status, message = "failed", "the step size fell to zero"
        if solver.status == "failed":
            if f.bad_t is not None:  # blame the cause, not the symptom ("step too small")
                raise _Stop(f"the right-hand side became non-finite at t = {f.bad_t:.6g} s")
            raise _Stop(f"solver failed at t = {solver.t:.6g} s: {message}")
        run.nsteps += 1
        if not _finite(solver.y):
            raise _Stop(f"state became non-finite at t = {solver.t:.6g} s")
        j = (
            len(t_eval)
            if solver.status == "finished"
            else np.searchsorted(t_eval, solver.t, "right")
        )
        if j > k:
            for y in solver.dense_output()(t_eval[k:j]).T:
                if not _finite(y):
                    raise _Stop(f"state became non-finite at t = {t_eval[k]:.6g} s")
                run.out.append(y)
                k += 1
        if f.watched(solver.t, solver.y):
            raise _Stop(f"a stop condition was reached near t = {solver.t:.6g} s")


_DOP853_CODES = {
    -1: "input is not consistent",
    -2: "step budget exhausted",
    -3: "step size became too small",
    -4: "the problem is probably stiff",
}


def _fortran(run: _Run, f: _Counted, y0, t_eval, rtol, atol, max_steps) -> None:
    """scipy's ``ode('dop853')`` lands on each output time in turn; budgets are checked after
    every accepted step by its `solout` hook (returning -1 interrupts the Fortran loop)."""
    f.watch = f.fortran = True

    def solout(t: float, y: np.ndarray) -> int:
        if f.failure is None and f.watched(t, y):
            f.failure = _Stop(f"a stop condition was reached near t = {t:.6g} s")
        return -1 if f.failure is not None or not _finite(y) else 0

    from scipy import integrate as si

    solver = si.ode(f).set_integrator("dop853", rtol=rtol, atol=atol, nsteps=max_steps)
    solver.set_solout(solout)
    solver.set_initial_value(y0, t_eval[0])
    for t1 in t_eval[1:]:
        if run.nsteps >= max_steps:
            raise _Stop(f"step budget ({max_steps}) exhausted at t = {solver.t:.6g} s")
        solver._integrator.call_args[6] = max_steps - run.nsteps  # NMAX of this call
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the failure is reported in the message instead
            y = solver.integrate(t1)
        run.nsteps += int(solver._integrator.iwork[17])  # NSTEP of this call: IWORK(18)
        if f.failure is not None:
            raise f.failure
        if not _finite(y):
            raise _Stop(f"state became non-finite at t = {solver.t:.6g} s")
        code = solver.get_return_code()
        if code < 0:
            if code == -2:
                raise _Stop(f"step budget ({max_steps}) exhausted at t = {solver.t:.6g} s")
            raise _Stop(f"dop853 failed at t = {solver.t:.6g} s: {_DOP853_CODES.get(code)}")
        run.out.append(np.array(y))


def _euler(f, t, y, h, n):
    """y ← y + h f(t, y): order 1; energy of oscillators grows by a factor (1 + h²ω²) a step."""
    return y + h * f(t, y)


def _symplectic_euler(f, t, y, h, n):
    """v ← v + h a(q, v); q ← q + h v_new (extra states: explicit Euler). Order 1; symplectic
    only for a constant mass matrix (v, not p = M(q) v, is what it steps)."""
    new = y + h * f(t, y)
    new[:n] = y[:n] + h * new[n : 2 * n]
    return new


def _rk4(f, t, y, h, n):
    """Classical Runge–Kutta: order 4, four evaluations, not symplectic (energy drifts)."""
    k1 = f(t, y)
    k2 = f(t + h / 2, y + h / 2 * k1)
    k3 = f(t + h / 2, y + h / 2 * k2)
    k4 = f(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def _implicit_midpoint(f, t, y, h, n):
    """y1 = y + h f(t + h/2, (y + y1)/2): order 2, A-stable, time-reversible; symplectic in
    (q, q̇) only when the mass matrix is constant.

    Fixed-point iteration (it contracts when h·|∂f/∂y|/2 < 1) to 1e-14 relative; if it has not
    converged in 50 iterations or diverges (stiff problems), Newton's method with a
    finite-difference Jacobian, started again from the explicit Euler guess.
    """
    tm = t + h / 2
    tol = 1e-14 * (1.0 + np.abs(y).max())
    guess = z = y + h * f(t, y)
    last = math.inf
    for _ in range(50):
        nxt = y + h * f(tm, (y + z) * 0.5)
        change = np.abs(nxt - z).max()
        z = nxt
        rate = change / last  # contraction factor ρ: the error left is about change·ρ/(1 − ρ)
        if change <= tol or (0 < rate < 0.5 and change * rate <= tol * (1 - rate)):
            return z
        if not rate < 1:  # diverging, stalled or non-finite
            break
        last = change
    z = guess
    eye = np.eye(len(y))
    for _ in range(25):
        mid = (y + z) / 2
        fm = f(tm, mid)
        jac = np.empty((len(y), len(y)))
        for j in range(len(y)):
            e = 1.4901161193847656e-08 * max(1.0, abs(mid[j]))  # sqrt(machine epsilon)
            probe = mid.copy()
            probe[j] += e
            jac[:, j] = (f(tm, probe) - fm) / e
        dz = np.linalg.solve(eye - h / 2 * jac, -(z - y - h * fm))
        z = z + dz
        if not _finite(z):
            return z  # the caller reports the non-finite state and when
        if np.abs(dz).max() <= tol:
            return z
    if np.abs(dz).max() <= 1e4 * tol:
        return z  # converged as far as rounding of the finite-difference Jacobian allows
    raise _Stop(f"implicit midpoint: the step equation did not converge at t = {t:.6g} s")


_STEPPERS = {
    "euler": _euler,
    "symplectic_euler": _symplectic_euler,
    "rk4": _rk4,
    "implicit_midpoint": _implicit_midpoint,
}
