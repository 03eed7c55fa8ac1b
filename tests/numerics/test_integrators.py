"""The integrator registry: each test compares with an independent expected value (a closed
form, a theoretical order or stability function, or scipy's own solve_ivp)."""

from __future__ import annotations

import math
import re
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mechanics.integrators import METHODS, integrate

FIXED = [name for name, m in METHODS.items() if m.kind == "fixed"]
ADAPTIVE = [name for name, m in METHODS.items() if m.kind == "adaptive"]


def oscillator(t, y):
    return np.array([y[1], -y[0]])  # y'' = -y: y = cos t from y(0) = 1, y'(0) = 0


def pendulum(t, y):
    return np.array([y[1], -math.sin(y[0])])


def pendulum_energy(y):
    return 0.5 * y[:, 1] ** 2 - np.cos(y[:, 0])


def error_vs_cos(run):
    return max(np.abs(run.y[:, 0] - np.cos(run.t)).max(), np.abs(run.y[:, 1] + np.sin(run.t)).max())


def stopped_at(message: str) -> float:
    return float(re.search(r"t = ([-+0-9.e]+)", message).group(1))


def test_registry_describes_every_method():
    assert set(FIXED) == {"euler", "symplectic_euler", "rk4", "implicit_midpoint"}
    assert {"RK45", "DOP853", "Radau", "BDF", "LSODA"} <= set(ADAPTIVE)
    for name, m in METHODS.items():
        assert m.name == name and m.label and m.description and m.order >= 1
    assert [n for n, m in METHODS.items() if m.symplectic] == [
        "symplectic_euler",
        "implicit_midpoint",
    ]


@pytest.mark.parametrize(
    ("method", "dt"),
    [("euler", 0.01), ("symplectic_euler", 0.01), ("rk4", 0.1), ("implicit_midpoint", 0.05)],
)
def test_fixed_step_methods_converge_at_their_order(method, dt):
    """Halving dt divides the error by 2^order."""
    t_eval = np.linspace(0, 2, 5)
    coarse = integrate(oscillator, [1.0, 0.0], t_eval, method=method, dt=dt)
    fine = integrate(oscillator, [1.0, 0.0], t_eval, method=method, dt=dt / 2)
    assert coarse.status == fine.status == "ok"
    observed = math.log2(error_vs_cos(coarse) / error_vs_cos(fine))
    assert observed == pytest.approx(METHODS[method].order, abs=0.15)


def test_fixed_steps_land_exactly_on_each_output_time():
    """Each interval gets ⌈Δt/dt⌉ equal steps: 3 + 1 + 7 for these gaps with dt = 0.1."""
    t_eval = np.array([0.0, 0.25, 0.3, 1.0])
    run = integrate(oscillator, [1.0, 0.0], t_eval, method="euler", dt=0.1)
    assert np.array_equal(run.t, t_eval) and run.nsteps == 11 and run.nfev == 11
    h = 0.25 / 3  # first interval: Euler's amplification matrix, applied three times
    step = np.array([[1.0, h], [-h, 1.0]])
    assert run.y[1] == pytest.approx(np.linalg.matrix_power(step, 3) @ [1.0, 0.0], rel=1e-13)


def test_pendulum_energy_over_1000_periods():
    """1000 periods (not 10⁴: pure-Python steps would take minutes) at dt = 0.2. Symplectic
    Euler's energy error stays bounded; RK4's drifts one way, explicit Euler's grows."""
    period = 6.6993  # amplitude 1 rad: 4 K(sin² ½) ≈ 6.6993 s
    t_eval = np.linspace(0, 1000 * period, 4001)  # not commensurate with the period
    drift = {}
    for method in ("symplectic_euler", "rk4"):
        run = integrate(pendulum, [1.0, 0.0], t_eval, method=method, dt=0.2)
        assert run.status == "ok"
        drift[method] = pendulum_energy(run.y) - pendulum_energy(run.y[:1])
    sym = np.abs(drift["symplectic_euler"])
    assert sym.max() < 0.06  # O(dt): the modified-energy oscillation
    assert sym[2000:].max() < 1.05 * sym[:2000].max()  # no growth from the first half
    chunks = drift["rk4"][1:].reshape(10, -1).mean(axis=1)
    assert np.all(np.diff(chunks) < 0)  # RK4 loses energy steadily...
    assert abs(chunks[-1]) > 5 * abs(chunks[0]) and abs(chunks[-1]) < 0.02  # ...and slowly
    euler = integrate(pendulum, [1.0, 0.0], t_eval[:21], method="euler", dt=0.01)
    chunks = (pendulum_energy(euler.y) - pendulum_energy(euler.y[:1]))[1:].reshape(4, -1).mean(1)
    assert np.all(np.diff(chunks) > 0) and chunks[-1] > 0.1


def test_implicit_midpoint_keeps_pendulum_energy_bounded():
    """100 periods at dt = 0.2 (each step iterates ~12 times: slower per step)."""
    t_eval = np.linspace(0, 100 * 6.6993, 2001)
    run = integrate(pendulum, [1.0, 0.0], t_eval, method="implicit_midpoint", dt=0.2)
    err = np.abs(pendulum_energy(run.y) - pendulum_energy(run.y[:1]))
    assert run.status == "ok" and err.max() < 1e-3  # O(dt²)
    assert err[1000:].max() < 1.01 * err[:1000].max()


def test_implicit_midpoint_conserves_a_quadratic_invariant_exactly():
    run = integrate(
        oscillator, [1.0, 0.0], np.linspace(0, 100, 11), method="implicit_midpoint", dt=0.1
    )
    assert np.abs(run.y[:, 0] ** 2 + run.y[:, 1] ** 2 - 1).max() < 1e-11


def test_implicit_midpoint_solves_a_stiff_step_by_newton():
    """y' = -1000 y, h = 0.01: fixed-point iteration diverges (h·1000/2 = 5 > 1); Newton gives
    the stability function R(z) = (1 + z/2)/(1 - z/2) at z = -10, i.e. -2/3 per step."""
    run = integrate(
        lambda t, y: -1000.0 * y, [1.0], np.array([0.0, 0.1]), method="implicit_midpoint", dt=0.01
    )
    assert run.status == "ok" and run.nsteps == 10
    assert run.y[-1, 0] == pytest.approx((-2 / 3) ** 10, rel=1e-9)
    assert run.nfev > 10 * 2  # Newton's finite differences are counted


@pytest.mark.parametrize("method", ADAPTIVE)
def test_adaptive_methods_reach_cos_t_to_about_the_tolerance(method):
    # multistep methods (BDF, LSODA) control the local error; their global error grows larger
    factor = 300 if method in ("BDF", "LSODA") else 10
    t_eval = np.linspace(0, 10, 101)
    for tol in (1e-6, 1e-9):
        run = integrate(oscillator, [1.0, 0.0], t_eval, method=method, rtol=tol, atol=tol)
        assert run.status == "ok" and np.array_equal(run.t, t_eval)
        assert run.y.shape == (101, 2)
        assert error_vs_cos(run) < factor * tol
        assert run.nfev > 0 and run.nsteps > 0 and run.wall_time > 0


@pytest.mark.parametrize("method", ["RK45", "DOP853", "Radau", "BDF", "LSODA"])
def test_adaptive_costs_match_scipy_solve_ivp(method):
    """Stepping by hand takes the same steps as solve_ivp; samples come from dense output."""
    t_eval = np.linspace(0, 10, 41)
    run = integrate(oscillator, [1.0, 0.0], t_eval, method=method, rtol=1e-8, atol=1e-8)
    ref = solve_ivp(
        oscillator, (0, 10), [1.0, 0.0], method=method, rtol=1e-8, atol=1e-8, dense_output=True
    )
    assert run.nsteps == len(ref.t) - 1
    assert run.njev == ref.njev
    if method == "RK45":  # the others: scipy's nfev leaves out finite-difference Jacobians, and
        assert run.nfev == ref.nfev  # DOP853's dense output is only built for steps with samples
    assert np.allclose(run.y, ref.sol(t_eval).T, rtol=0, atol=1e-14)


@pytest.mark.parametrize("method", ["Radau", "BDF", "LSODA"])
def test_stiff_linear_problem_is_solved_quickly_and_correctly(method):
    """y' = -λ(y - cos t), y(0) = 0, λ = 10⁶: y = A cos t + B sin t - A e^(-λt), A = λ²/(1+λ²),
    B = λ/(1+λ²). An explicit method would need ~10⁶ steps (its stability limit)."""
    lam = 1e6
    t_eval = np.linspace(0, 10, 51)
    start = time.perf_counter()
    run = integrate(
        lambda t, y: -lam * (y - math.cos(t)), [0.0], t_eval, method=method, rtol=1e-8, atol=1e-10
    )
    a, b = lam**2 / (1 + lam**2), lam / (1 + lam**2)
    expected = a * np.cos(t_eval) + b * np.sin(t_eval) - a * np.exp(-lam * t_eval)
    assert run.status == "ok" and time.perf_counter() - start < 2
    assert run.y[-1, 0] == pytest.approx(expected[-1], abs=1e-7)  # a step end: full order
    # between step ends the samples come from the dense output; Radau's (its collocation
    # polynomial, stage order 3) is much less accurate on stiff problems than its steps
    samples = 1e-3 if method == "Radau" else 1e-7
    assert np.abs(run.y[:, 0] - expected).max() < samples
    assert 0 < run.nsteps < 2000 and run.nfev > 0 and run.njev > 0


def test_explicit_method_on_a_stiff_problem_stops_at_the_step_budget():
    run = integrate(
        lambda t, y: -1e6 * (y - math.cos(t)),
        [0.0],
        np.linspace(0, 10, 11),
        method="RK45",
        max_steps=500,
    )
    assert run.status == "stopped" and "step budget (500)" in run.message
    assert run.nsteps == 500 and run.t[-1] < 10


def nan_after_one(t, y):
    return np.array([y[1], -y[0]]) if t <= 1 else np.array([np.nan, np.nan])


@pytest.mark.parametrize("method", list(METHODS))
def test_a_non_finite_state_stops_the_run_and_says_when(method):
    t_eval = np.linspace(0, 3, 31)
    run = integrate(nan_after_one, [1.0, 0.0], t_eval, method=method, dt=0.05)
    assert run.status == "stopped" and "non-finite" in run.message
    assert 0.9 <= run.t[-1] <= 1.1 and len(run.y) == len(run.t)
    assert np.all(np.isfinite(run.y))
    assert run.y[:, 0] == pytest.approx(np.cos(run.t), abs=0.05)
    assert 1.0 <= stopped_at(run.message) <= 1.2


def sleepy(t, y):
    time.sleep(0.005)
    return np.array([y[1], -y[0]])


@pytest.mark.parametrize("method", ["rk4", "RK45", "Radau", "LSODA", "dop853_fortran"])
def test_the_wall_time_budget_stops_a_slow_run(method):
    start = time.perf_counter()
    run = integrate(
        sleepy, [1.0, 0.0], np.linspace(0, 100, 101), method=method, dt=0.01, max_wall_time=0.2
    )
    elapsed = time.perf_counter() - start
    assert run.status == "stopped" and "wall-time budget" in run.message
    assert 0.2 <= elapsed < 1.2 and run.wall_time == pytest.approx(elapsed, abs=0.2)
    assert len(run.t) < 101 and len(run.y) == len(run.t)


def test_an_exception_in_the_rhs_of_the_fortran_method_is_raised_not_fatal():
    def broken(t, y):
        if t > 1:
            raise RuntimeError("bug in the model")
        return oscillator(t, y)

    with pytest.raises(RuntimeError, match="bug in the model"):
        integrate(broken, [1.0, 0.0], np.linspace(0, 3, 4), method="dop853_fortran")


@pytest.mark.parametrize("method", ["rk4", "DOP853"])
def test_a_single_output_time_returns_the_initial_state(method):
    run = integrate(oscillator, [1.0, 0.5], np.array([2.0]), method=method, dt=0.1)
    assert run.status == "ok" and run.t.tolist() == [2.0]
    assert run.y.tolist() == [[1.0, 0.5]] and run.nfev == 0 and run.nsteps == 0


def test_unknown_method_lists_the_valid_names():
    with pytest.raises(ValueError, match="unknown method 'rk5'") as err:
        integrate(oscillator, [1.0, 0.0], [0.0, 1.0], method="rk5")
    assert all(name in str(err.value) for name in METHODS)


@pytest.mark.parametrize("dt", [None, 0.0, -0.1, math.nan])
def test_fixed_step_methods_need_a_positive_step(dt):
    with pytest.raises(ValueError, match="fixed-step method: give a finite step dt > 0"):
        integrate(oscillator, [1.0, 0.0], [0.0, 1.0], method="rk4", dt=dt)


def test_symplectic_euler_uses_the_new_velocity_and_the_second_order_split():
    """One step by hand: v₁ = v₀ + h a(q₀), q₁ = q₀ + h v₁; the extra state w' = v rides along
    with an explicit Euler step."""
    run = integrate(
        lambda t, y: np.array([y[1], -y[0], y[1]]),
        [1.0, 0.5, 0.0],
        [0.0, 0.1],
        method="symplectic_euler",
        dt=0.1,
        second_order=1,
    )
    v1 = 0.5 - 0.1 * 1.0
    assert run.y[-1] == pytest.approx([1.0 + 0.1 * v1, v1, 0.1 * 0.5], rel=1e-15)
    with pytest.raises(ValueError, match="second_order"):
        integrate(oscillator, [1.0, 0.0, 0.0], [0.0, 1.0], method="symplectic_euler", dt=0.1)
