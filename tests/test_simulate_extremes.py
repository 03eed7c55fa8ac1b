"""The numerics stay honest at the extremes: each test has an independent expected value."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ellipk

from mechanics.integrators import integrate
from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError


def crossings(t, q, qd, level=0.0, direction=-1):
    """Times where q crosses `level` going `direction`, refined by cubic Hermite interpolation."""
    t, q, qd = (np.asarray(a) for a in (t, q, qd))
    out = []
    for i in range(len(t) - 1):
        a, b = q[i] - level, q[i + 1] - level
        if a == 0 or a * b >= 0 or (b - a) * direction < 0:
            continue
        h = t[i + 1] - t[i]
        lo, hi = 0.0, 1.0
        for _ in range(60):  # bisection on the Hermite cubic between the two samples
            s = (lo + hi) / 2
            h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
            h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
            v = h00 * a + h10 * h * qd[i] + h01 * b + h11 * h * qd[i + 1]
            lo, hi = (s, hi) if v * a > 0 else (lo, s)
        out.append(t[i] + lo * h)
    return out


def hermite(t, q, qd, at):
    """q at time `at` by cubic Hermite interpolation between the samples around it."""
    t = np.asarray(t)
    i = int(np.searchsorted(t, at)) - 1
    h = t[i + 1] - t[i]
    s = (at - t[i]) / h
    return (
        (2 * s**3 - 3 * s**2 + 1) * q[i]
        + (s**3 - 2 * s**2 + s) * h * qd[i]
        + (-2 * s**3 + 3 * s**2) * q[i + 1]
        + (s**3 - s**2) * h * qd[i + 1]
    )


def pendulum(theta0, t_end, **kw):
    req = SimulationRequest(
        initial={"theta": theta0, "theta_dot": 0.0}, t_end=t_end, check_sensitivity=False, **kw
    )
    return simulate(scene_id="simple_pendulum", request=req)


def elliptic_period(theta0, length=1.0, g=9.81):
    return 4 * math.sqrt(length / g) * ellipk(math.sin(theta0 / 2) ** 2)


def test_pendulum_at_170_degrees_has_the_elliptic_integral_period():
    theta0 = math.radians(170)
    r = pendulum(theta0, 12, fps=240, method="DOP853", rtol=1e-13, atol=1e-13)
    down = crossings(r["t"], r["q"]["theta"], r["q_dot"]["theta"])
    period = down[1] - down[0]
    assert period == pytest.approx(elliptic_period(theta0), rel=1e-8)


def test_pendulum_at_179_999_degrees_stays_finite_and_right():
    theta0 = math.radians(179.999)
    expected = elliptic_period(theta0)
    r = pendulum(theta0, 2.2 * expected, fps=120, method="DOP853", rtol=1e-13, atol=1e-13)
    assert np.all(np.isfinite(r["q"]["theta"]))
    down = crossings(r["t"], r["q"]["theta"], r["q_dot"]["theta"])
    # 0.001° from the top the energy sits 1.5e-9 J below the separatrix and T ∝ ln(1/gap):
    # an energy error of 1e-12 J already moves T by ~1e-5 of itself. That is the honest bound.
    assert down[1] - down[0] == pytest.approx(expected, rel=1e-4)


def test_near_inverted_pendulum_warns_that_the_result_is_sensitive():
    req = SimulationRequest(
        initial={"theta": math.radians(179.999)}, t_end=20, method="RK45", rtol=1e-9, atol=1e-9
    )
    r = simulate(scene_id="simple_pendulum", request=req)
    assert any("sensitive" in w for w in r["warnings"]), r["warnings"]


def test_kepler_orbit_e_0_9_keeps_its_period_and_perihelion():
    e, a, gm = 0.9, 10.0, 1.0
    r_p = a * (1 - e)
    theta_dot0 = math.sqrt(gm * (1 + e) / r_p) / r_p
    period = 2 * math.pi * math.sqrt(a**3 / gm)
    req = SimulationRequest(
        initial={"r": r_p, "r_dot": 0.0, "theta": 0.0, "theta_dot": theta_dot0},
        t_end=period * 1.05,
        fps=60,
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        check_sensitivity=False,
    )
    res = simulate(scene_id="central_force", request=req)
    t, th, thd = res["t"], res["q"]["theta"], res["q_dot"]["theta"]
    (t_orbit,) = crossings(t, th, thd, level=2 * math.pi, direction=1)
    assert t_orbit == pytest.approx(period, rel=1e-8)
    r_at = hermite(t, res["q"]["r"], res["q_dot"]["r"], t_orbit)
    assert r_at == pytest.approx(r_p, rel=1e-6)
    assert res["stats"]["energy_error"] < 1e-8
    assert res["stats"]["momentum_drift"]["theta"] < 1e-9


def test_double_pendulum_energy_error_at_tight_tolerance():
    req = SimulationRequest(
        t_end=20, method="DOP853", rtol=1e-12, atol=1e-12, check_sensitivity=False
    )
    r = simulate(scene_id="double_pendulum", request=req)
    assert r["stats"]["energy_error"] <= 1e-9


def _pendulum_energy(y):
    return 0.5 * y[:, 1] ** 2 - np.cos(y[:, 0])


def _rhs(t, y):
    return np.array([y[1], -math.sin(y[0])])


def test_symplectic_euler_stays_bounded_where_rk4_drifts_and_euler_grows():
    """10⁴ periods of a pendulum (amplitude 1 rad), dt = 0.2."""
    periods = 10_000
    t_eval = np.linspace(0, periods * 2 * math.pi, 201)
    y0 = np.array([1.0, 0.0])
    drift = {}
    for method in ("symplectic_euler", "rk4"):
        run = integrate(_rhs, y0, t_eval, method=method, dt=0.2, max_wall_time=60)
        assert run.status == "ok"
        E = _pendulum_energy(run.y)
        drift[method] = np.abs(E - E[0])
    # symplectic Euler: bounded oscillation, no trend between the first and last halves
    half = len(t_eval) // 2
    assert drift["symplectic_euler"].max() < 0.05
    assert drift["symplectic_euler"][half:].max() < 2 * drift["symplectic_euler"][:half].max()
    # RK4: a steady one-way drift, growing with time
    assert drift["rk4"][-1] > 5 * drift["rk4"][len(t_eval) // 10]
    euler = integrate(_rhs, y0, t_eval[:21], method="euler", dt=0.2)
    assert np.abs(_pendulum_energy(euler.y)[-1] - _pendulum_energy(euler.y)[0]) > 1


def stiff_spring(method, **kw):
    """k/m = 1e8 and heavy damping: modes at λ ≈ −100 and −1e6 s⁻¹, a stiffness ratio of 1e4."""
    k, m, c, x0 = 1e8, 1.0, 1e6, 0.01
    req = SimulationRequest(
        parameters={"k": k, "m": m, "c": c, "F0": 0.0},
        initial={"x": x0, "x_dot": 0.0},
        t_end=0.05,
        fps=240,
        method=method,
        check_sensitivity=False,
        **kw,
    )
    r = simulate(scene_id="spring_mass_damper", request=req)
    root = math.sqrt(c**2 - 4 * m * k)
    l1, l2 = (-c + root) / (2 * m), (-c - root) / (2 * m)
    t = np.asarray(r["t"])
    expected = x0 / (l2 - l1) * (l2 * np.exp(l1 * t) - l1 * np.exp(l2 * t))
    return r, expected


@pytest.mark.parametrize("method", ["Radau", "BDF"])
def test_stiff_spring_implicit_methods_finish_correctly_and_cheaply(method):
    r, expected = stiff_spring(method, rtol=1e-8, atol=1e-12)
    assert r["stats"]["status"] == "ok"
    assert r["stats"]["steps"] < 2000
    assert np.allclose(r["q"]["x"], expected, rtol=1e-5, atol=1e-9)


def test_stiff_spring_explicit_method_is_slow_and_correct_or_says_why_not():
    r, expected = stiff_spring("RK45", rtol=1e-8, atol=1e-12)
    implicit, _ = stiff_spring("Radau", rtol=1e-8, atol=1e-12)
    if r["stats"]["status"] == "ok":
        assert np.allclose(r["q"]["x"], expected, rtol=1e-5, atol=1e-9)
        assert r["stats"]["rhs_evaluations"] > 5 * implicit["stats"]["rhs_evaluations"]
    else:
        assert any("Radau" in w or "stiff" in w for w in r["warnings"])


def test_spherical_pendulum_through_the_pole_has_no_nan_and_keeps_energy():
    req = SimulationRequest(
        initial={"theta": 0.6, "theta_dot": 0.0, "phi": 0.0, "phi_dot": 1e-3},
        t_end=3,
        fps=240,
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        check_sensitivity=False,
    )
    r = simulate(scene_id="spherical_pendulum", request=req)
    theta = np.asarray(r["q"]["theta"])
    assert np.all(np.isfinite(theta)) and np.all(np.isfinite(r["q"]["phi"]))
    assert r["stats"]["energy_error"] < 1e-6
    if theta.min() < 1e-3:
        assert any("singular" in w for w in r["warnings"]), r["warnings"]


def test_tiny_mass_and_huge_length_pendulum_follow_the_small_angle_solution():
    theta0, length, g = 1e-3, 1e6, 9.81
    req = SimulationRequest(
        parameters={"m": 1e-9, "l": length},
        initial={"theta": theta0},
        t_end=1000,
        fps=1,
        method="DOP853",
        rtol=1e-12,
        atol=1e-15,
        check_sensitivity=False,
    )
    r = simulate(scene_id="simple_pendulum", request=req)
    t = np.asarray(r["t"])
    expected = theta0 * np.cos(math.sqrt(g / length) * t)
    assert np.allclose(r["q"]["theta"], expected, atol=1e-6 * theta0)


def test_undriven_damped_oscillator_matches_its_closed_form():
    m, k, c, x0 = 1.0, 10.0, 0.4, 0.3
    req = SimulationRequest(
        parameters={"F0": 0.0},
        initial={"x": x0},
        t_end=10,
        fps=30,
        rtol=1e-12,
        atol=1e-12,
        check_sensitivity=False,
    )
    r = simulate(scene_id="spring_mass_damper", request=req)
    w0, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
    wd = w0 * math.sqrt(1 - zeta**2)
    t = np.asarray(r["t"])
    expected = np.exp(-zeta * w0 * t) * (x0 * np.cos(wd * t) + zeta * w0 * x0 / wd * np.sin(wd * t))
    assert np.allclose(r["q"]["x"], expected, atol=1e-9)


def test_zero_duration_returns_the_initial_state():
    r = simulate(scene_id="double_pendulum", request=SimulationRequest(t_end=0))
    spec = load_scene("double_pendulum")
    assert r["t"] == [0.0]
    assert r["q"]["theta1"] == [spec["initial"]["theta1"]]


def test_a_blow_up_stops_with_the_partial_trajectory_and_says_when():
    run = integrate(
        lambda t, y: np.array([y[0] ** 2]),
        np.array([1.0]),
        np.linspace(0, 2, 201),
        method="RK45",
        rtol=1e-8,
        atol=1e-8,
    )
    assert run.status == "stopped"
    assert run.t[-1] <= 1.0  # y = 1/(1 − t) blows up at t = 1
    assert "t =" in run.message
    spec = {
        "title": "falling into a singular well",
        "coordinates": ["x"],
        "parameters": {"m": 1.0},
        "bodies": [{"name": "p", "mass": "m", "position": ["x", 0]}],
        "potentials": [{"name": "well", "expression": "-1/(1 - x)**2"}],
        "initial": {"x": 0.0},
    }
    r = simulate(scene=spec, request=SimulationRequest(t_end=5, check_sensitivity=False))
    assert r["stats"]["status"] == "stopped"
    assert any("stopped early" in w for w in r["warnings"])
    assert len(r["t"]) < 5 * 60 + 1 and np.all(np.isfinite(r["q"]["x"]))


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"parameters": {"m": -1.0}}, "parameters.m"),
        ({"initial": {"theta": float("nan")}}, "initial.theta"),
        ({"parameters": {"nope": 1.0}}, "parameters.nope"),
        ({"t_end": 1e6}, "t_end"),
        ({"fps": 0.0}, "fps"),
        ({"method": "rk4"}, "dt"),
    ],
)
def test_bad_requests_name_their_field(changes, field):
    with pytest.raises(SpecError) as err:
        simulate(scene_id="simple_pendulum", request=SimulationRequest(**changes))
    assert field in [e["field"] for e in err.value.errors]
