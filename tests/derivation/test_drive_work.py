"""The work of whatever drives a system: ΔT + ΔV = W_nc + W_drive along every run.

Each expected W_drive is computed here from the agent that does the work, not from the
Lagrangian the engine uses: the motor torque that keeps a hoop spinning (τ Ω = Ω dL_y/dt), the
force a shaken pivot exerts on its rod times the pivot's velocity, and ∫ ∂V/∂t dt for a potential
that changes in time. The motions themselves come from hand-written equations and solve_ivp.
"""

from __future__ import annotations

import numpy as np
import pytest
from independent import own_run

from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate

TIGHT = {"rtol": 1e-11, "atol": 1e-12}


def assert_balance(result, rel=1e-7):
    """ΔT + ΔV = W_nc + W_drive at every sample, relative to the largest energy in play."""
    e = result["energy"]
    T, V = np.array(e["T"]), np.array(e["V"])
    w_nc, w_drive = np.array(e["W_nc"]), np.array(e["W_drive"])
    lhs = (T - T[0]) + (V - V[0])
    scale = max(np.max(np.abs(T)), np.max(np.abs(w_drive)), np.max(np.abs(w_nc)))
    assert np.max(np.abs(lhs - w_nc - w_drive)) <= rel * scale


def assert_no_drift_warning(result):
    assert not any("drifted" in w for w in result["warnings"]), result["warnings"]


# --- a bead on a hoop spun at Ω: the motor's work --------------------------------------------


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "Radau"])
def test_the_hoop_motor_does_the_work_omega_times_the_change_of_angular_momentum(method):
    spec = load_scene("bead_on_hoop")
    p = spec["parameters"]
    m, R, Om, g = p["m"], p["R"], p["Omega"], p["g"]
    th0, thd0 = spec["initial"]["theta"], spec["initial"].get("theta_dot", 0.0)
    result = simulate(
        scene_id="bead_on_hoop",
        request=SimulationRequest(t_end=3.0, fps=40, method=method, **TIGHT),
    )
    t = np.array(result["t"])

    def bead(t, y):  # θ̈ = sin θ (Ω² cos θ − g/R)
        th, thd = y
        return [thd, np.sin(th) * (Om**2 * np.cos(th) - g / R)]

    sol = own_run(bead, [th0, thd0], t)
    th, thd = sol.y
    np.testing.assert_allclose(result["q"]["theta"], th, atol=1e-7)
    # The motor holds Ω fixed: its torque about the vertical is dL_y/dt with L_y = m R² sin²θ Ω,
    # so it does W = ∫ τ Ω dt = Ω ΔL_y = m R² Ω² (sin²θ − sin²θ₀).
    w_motor = m * R**2 * Om**2 * (np.sin(th) ** 2 - np.sin(th0) ** 2)
    scale = np.max(np.abs(w_motor))
    np.testing.assert_allclose(result["energy"]["W_drive"], w_motor, atol=1e-7 * scale)
    # T and V written by hand from the bead's speed in N: (R θ̇)² + (Ω R sin θ)².
    T = 0.5 * m * R**2 * (thd**2 + Om**2 * np.sin(th) ** 2)
    V = -m * g * R * np.cos(th)
    np.testing.assert_allclose(result["energy"]["T"], T, atol=1e-7 * np.max(T))
    np.testing.assert_allclose(result["energy"]["V"], V, atol=1e-7 * np.max(np.abs(V)))
    assert_balance(result)
    assert result["stats"]["driven"] is True
    assert result["stats"]["jacobi_error"] < 1e-8
    assert_no_drift_warning(result)


# --- a pendulum whose pivot is shaken: x_s = a cos(w t) --------------------------------------

SHAKEN = {
    "title": "Pendulum on a shaken pivot",
    "coordinates": ["theta"],
    "parameters": {"m": 0.5, "l": 1.0, "g": 9.81, "a": 0.2, "w": 2.5},
    "bodies": [
        {
            "name": "bob",
            "mass": "m",
            "position": ["a*cos(w*t) + l*sin(theta)", "-l*cos(theta)", 0],
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    "initial": {"theta": 0.4, "theta_dot": 0.0},
}


@pytest.mark.parametrize("method", ["DOP853", "dop853_c"])
def test_a_shaken_pivot_does_the_work_of_the_rod_force_times_the_pivot_velocity(method):
    p = SHAKEN["parameters"]
    m, length, g, a, w = p["m"], p["l"], p["g"], p["a"], p["w"]
    result = simulate(
        scene=SHAKEN, request=SimulationRequest(t_end=6.0, fps=20, method=method, **TIGHT)
    )

    def shaken(t, y):
        th, thd, _ = y
        # length θ̈ = −g sin θ − ẍ_s cos θ, ẍ_s = −a w² cos(w t)
        thdd = (-g * np.sin(th) + a * w**2 * np.cos(w * t) * np.cos(th)) / length
        # The massless pivot passes the rod's horizontal pull on the bob, m ẍ_bob, to the drive;
        # only that component works, the pivot moving horizontally at ẋ_s = −a w sin(w t).
        x_bob_ddot = -a * w**2 * np.cos(w * t) + length * (thdd * np.cos(th) - thd**2 * np.sin(th))
        return [thd, thdd, m * x_bob_ddot * (-a * w * np.sin(w * t))]

    sol = own_run(shaken, [0.4, 0.0, 0.0], np.array(result["t"]))
    np.testing.assert_allclose(result["q"]["theta"], sol.y[0], atol=1e-7)
    scale = np.max(np.abs(sol.y[2]))
    assert scale > 0.05  # the drive really does work here
    np.testing.assert_allclose(result["energy"]["W_drive"], sol.y[2], atol=1e-7 * scale)
    assert_balance(result)
    assert result["stats"]["driven"] is True
    assert result["stats"]["energy_balance_error"] < 1e-7
    assert_no_drift_warning(result)


# --- a potential that changes in time, with a dashpot ----------------------------------------

BREATHING = {
    "title": "A spring whose stiffness breathes",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 4.0, "eps": 0.3, "w": 3.0, "c": 0.2},
    "bodies": [{"name": "block", "mass": "m", "position": ["x", 0, 0]}],
    "potentials": [{"name": "breathing", "expression": "k*(1 + eps*sin(w*t))*x**2/2"}],
    "dampers": [{"a": "O", "b": "block", "c": "c"}],
    "initial": {"x": 1.0, "x_dot": 0.0},
}


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4"])
def test_a_time_dependent_potential_does_the_work_of_its_time_derivative(method):
    p = BREATHING["parameters"]
    m, k, eps, w, c = p["m"], p["k"], p["eps"], p["w"], p["c"]
    fixed = {"dt": 1e-3} if method == "rk4" else {}
    result = simulate(
        scene=BREATHING,
        request=SimulationRequest(t_end=5.0, fps=20, method=method, **TIGHT, **fixed),
    )

    def breathing(t, y):
        x, v, _, _ = y
        kt = k * (1 + eps * np.sin(w * t))
        return [
            v,
            (-kt * x - c * v) / m,
            -c * v * v,  # W_nc: the dashpot
            0.5 * k * eps * w * np.cos(w * t) * x * x,  # W_drive: ∫ ∂V/∂t dt
        ]

    sol = own_run(breathing, [1.0, 0.0, 0.0, 0.0], np.array(result["t"]))
    atol = 1e-6 if method == "rk4" else 1e-7
    np.testing.assert_allclose(result["q"]["x"], sol.y[0], atol=atol)
    np.testing.assert_allclose(result["energy"]["W_nc"], sol.y[2], atol=atol)
    scale = np.max(np.abs(sol.y[3]))
    assert scale > 0.05
    np.testing.assert_allclose(result["energy"]["W_drive"], sol.y[3], atol=atol * scale)
    assert_balance(result, rel=1e-7 if method != "rk4" else 1e-6)
    assert result["stats"]["driven"] is True
    assert result["stats"]["energy_balance_error"] < 1e-6
    assert_no_drift_warning(result)


# --- nothing drives these ----------------------------------------------------------------------


@pytest.mark.parametrize("scene_id", ["simple_pendulum", "spring_mass_damper", "atwood_machine"])
def test_an_undriven_scene_says_so_and_its_drive_work_is_zero(scene_id):
    result = simulate(scene_id=scene_id, request=SimulationRequest(t_end=0.5, fps=20))
    assert result["stats"]["driven"] is False
    assert result["energy"]["W_drive"] == [0.0] * len(result["t"])
