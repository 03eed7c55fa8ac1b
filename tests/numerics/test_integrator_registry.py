"""The integrator registry keeps the promises of its metadata, and bad requests name their field.

Expected values are independent of the code under test: the closed form y = cos t of y'' = -y, the
order each METHODS entry states, the number of stages of a method, the local-error criterion of
an adaptive solver, a clock. Nothing here compares against numbers printed by the code itself.
"""

from __future__ import annotations

import math
import re
import time

import numpy as np
import pytest

from mechanics.integrators import METHODS, integrate
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError

FIXED = [name for name, m in METHODS.items() if m.kind == "fixed"]
ADAPTIVE = [name for name, m in METHODS.items() if m.kind == "adaptive"]
#: Variable-order families: METHODS states their *maximum* order (BDF 5, LSODA's Adams 12).
VARIABLE_ORDER = {"BDF", "LSODA"}


def oscillator(t, y):
    """y'' = -y as a first-order system; from y(0) = 1, y'(0) = 0: y = cos t, y' = -sin t."""
    return np.array([y[1], -y[0]])


def exact(t):
    t = np.asarray(t, dtype=float)
    return np.stack([np.cos(t), -np.sin(t)], axis=1)


def max_error(run) -> float:
    return float(np.abs(run.y - exact(run.t)).max())


# --- order of convergence -------------------------------------------------------------------

#: A first step small enough to be in the asymptotic range, large enough to stay above rounding.
FIRST_DT = {"euler": 0.01, "symplectic_euler": 0.01, "rk4": 0.05, "implicit_midpoint": 0.02}


def test_every_fixed_method_has_a_convergence_step():
    assert set(FIRST_DT) == set(FIXED)


@pytest.mark.parametrize("method", FIXED)
def test_fixed_step_error_falls_by_2_to_the_order_when_dt_halves(method):
    t_eval = np.linspace(0, 2 * math.pi, 9)
    errors = []
    for dt in (FIRST_DT[method], FIRST_DT[method] / 2, FIRST_DT[method] / 4):
        run = integrate(oscillator, [1.0, 0.0], t_eval, method=method, dt=dt)
        assert run.status == "ok"
        errors.append(max_error(run))
    order = METHODS[method].order
    for coarse, fine in zip(errors, errors[1:], strict=False):
        # error ≈ C·dt^p: each halving divides it by 2^p (log2 of the ratio within ±0.2 of p)
        assert math.log2(coarse / fine) == pytest.approx(order, abs=0.2)


@pytest.mark.parametrize("method", ADAPTIVE)
def test_adaptive_error_falls_with_the_step_count_at_the_stated_order(method):
    """Global error ≈ C·N^(-p) for N steps: the slope of log(error) against log(N) over a range
    of tolerances is the order. Variable-order families climb to high order on this smooth
    problem; for them only a loose band around their maximum order is meaningful."""
    t_eval = np.array([0.0, 5.0, 10.0])
    tols = (1e-5, 1e-7, 1e-9) if method == "Radau" else (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
    steps, errors = [], []
    for tol in tols:
        run = integrate(oscillator, [1.0, 0.0], t_eval, method=method, rtol=tol, atol=tol)
        assert run.status == "ok"
        steps.append(run.nsteps)
        errors.append(max_error(run))
    slope = -np.polyfit(np.log(steps), np.log(errors), 1)[0]
    order = METHODS[method].order
    if method in VARIABLE_ORDER:
        assert 2 <= slope <= order + 2.5, slope
    else:
        # faster than stated is harmless (superconvergence on a linear problem); slower is not
        assert order - 1.5 <= slope <= order + 2.5, slope


@pytest.mark.parametrize("method", ADAPTIVE)
def test_adaptive_methods_meet_their_tolerance(method):
    """Each accepted step keeps its local error estimate within the weighted RMS norm:
    |e_i| ≤ sqrt(2)·(atol + rtol·|y_i|) ≤ sqrt(2)·(atol + rtol) here (|y_i| ≤ 1). The flow of
    y'' = -y is a rotation (it preserves |y|), so local errors add up without amplification:
    the global error is at most the sum of the N local errors, ≤ 2·(N + 1)·(atol + rtol)."""
    for tol in (1e-6, 1e-9):
        t_eval = np.linspace(0, 10, 201)
        run = integrate(oscillator, [1.0, 0.0], t_eval, method=method, rtol=tol, atol=tol)
        assert run.status == "ok" and np.array_equal(run.t, t_eval)
        assert max_error(run) <= 2 * (run.nsteps + 1) * (2 * tol)
    # A tighter tolerance buys accuracy: 1000× tighter, at least 20× smaller errors. (Few output
    # times here: dop853_fortran lands on each one, and 200 landings alone reach rounding.)
    errors = [
        max_error(integrate(oscillator, [1.0, 0.0], [0.0, 10.0], method=method, rtol=tol, atol=tol))
        for tol in (1e-6, 1e-9)
    ]
    assert errors[1] < errors[0] / 20


# --- costs follow the structure of each method ---------------------------------------------


@pytest.mark.parametrize(("method", "stages"), [("euler", 1), ("symplectic_euler", 1), ("rk4", 4)])
def test_fixed_explicit_methods_cost_their_stage_count_per_step(method, stages):
    t_eval = np.array([0.0, 0.25, 0.3, 1.0])
    run = integrate(oscillator, [1.0, 0.0], t_eval, method=method, dt=0.1)
    # each interval gets ceil(Δt/dt) equal steps: 3 + 1 + 7
    assert run.nsteps == 11
    assert run.nfev == stages * run.nsteps
    assert np.array_equal(run.t, t_eval)


# --- edges of the interface -----------------------------------------------------------------


@pytest.mark.parametrize("method", list(METHODS))
def test_a_single_output_time_returns_the_initial_state_for_every_method(method):
    run = integrate(oscillator, [0.3, -0.7], np.array([2.5]), method=method, dt=0.1)
    assert run.status == "ok" and run.message == ""
    assert run.t.tolist() == [2.5]
    assert run.y.tolist() == [[0.3, -0.7]]
    assert run.nfev == 0 and run.nsteps == 0


def test_an_unknown_method_is_a_value_error_listing_the_valid_ones():
    with pytest.raises(ValueError, match="unknown method") as err:
        integrate(oscillator, [1.0, 0.0], [0.0, 1.0], method="leapfrog")
    assert all(name in str(err.value) for name in METHODS)


@pytest.mark.parametrize("method", FIXED)
@pytest.mark.parametrize("t_eval", [[0.0, 1.0], [0.0]])
def test_a_fixed_step_method_without_dt_is_a_value_error(method, t_eval):
    with pytest.raises(ValueError, match="dt"):
        integrate(oscillator, [1.0, 0.0], t_eval, method=method)


def sleepy(t, y):
    time.sleep(0.003)
    return np.array([y[1], -y[0]])


@pytest.mark.parametrize("method", list(METHODS))
def test_the_wall_time_budget_stops_a_sleeping_rhs_near_the_budget(method):
    budget = 0.15
    t_eval = np.linspace(0, 50, 51)
    start = time.perf_counter()
    run = integrate(sleepy, [1.0, 0.0], t_eval, method=method, dt=0.01, max_wall_time=budget)
    elapsed = time.perf_counter() - start
    assert run.status == "stopped"
    assert "wall-time" in run.message
    # the clock is checked before every RHS call, so the overshoot is about one call; the
    # bound is loose because a busy CI machine stretches any wall clock
    assert budget <= elapsed < budget + 1.0
    assert run.wall_time == pytest.approx(elapsed, abs=0.2)
    stopped = float(re.search(r"t = ([-+0-9.e]+)", run.message).group(1))
    assert 0 <= stopped < 50
    # what it has is a prefix of the requested samples, and right
    assert np.array_equal(run.t, t_eval[: len(run.t)]) and len(run.y) == len(run.t)
    assert np.abs(run.y - exact(run.t)).max() < 1e-2


# --- simulate(): a bad request names its field ----------------------------------------------


@pytest.mark.parametrize(
    ("changes", "field", "words"),
    [
        ({"parameters": {"m": -1.0}}, "parameters.m", "≥ 0"),
        ({"parameters": {"l": math.inf}}, "parameters.l", "finite"),
        ({"initial": {"theta": math.nan}}, "initial.theta", "finite"),
        ({"initial": {"phi": 1.0}}, "initial.phi", "unknown coordinate"),
        ({"parameters": {"zeta": 1.0}}, "parameters.zeta", "unknown parameter"),
        ({"t_end": 1e6}, "t_end", "between"),
        ({"t_end": -1.0}, "t_end", "between"),
        ({"fps": 0.0}, "fps", "> 0"),
        ({"method": "rk4"}, "dt", "dt > 0"),
        ({"method": "euler", "dt": 0.0}, "dt", "dt > 0"),
        ({"method": "ode45"}, "method", "unknown method"),
        ({"rtol": 0.0}, "rtol", "1e-14"),
    ],
)
def test_a_bad_simulation_request_raises_spec_error_naming_the_field(changes, field, words):
    with pytest.raises(SpecError) as err:
        simulate(scene_id="simple_pendulum", request=SimulationRequest(**changes))
    fields = {e["field"]: e["message"] for e in err.value.errors}
    assert field in fields, fields
    assert words in fields[field]


def test_every_bad_field_of_a_request_is_reported_at_once():
    req = SimulationRequest(
        parameters={"m": -2.0, "zeta": 1.0}, initial={"theta": math.nan}, t_end=1e6, fps=0.0
    )
    with pytest.raises(SpecError) as err:
        simulate(scene_id="simple_pendulum", request=req)
    fields = {e["field"] for e in err.value.errors}
    assert {"parameters.m", "parameters.zeta", "initial.theta", "t_end", "fps"} <= fields
