"""What the energy warning and the method descriptions claim, checked against the energies.

Energies are computed here from the returned q, q̇ with the scenes' textbook formulas (not the
response's E); a claim of boundedness is checked against the run's own floor and ceiling. The
symplectic methods step (q, q̇), not the momenta, so they are symplectic only for a constant
mass matrix: the double pendulum is where they drift.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from mechanics.integrators import METHODS
from mechanics.simulate import SimulationRequest, _error_trend, simulate

G = 9.81


def _double_pendulum_energy(d: dict) -> np.ndarray:
    """m1 = m2 = l1 = l2 = 1, absolute angles from the downward vertical."""
    a, b = np.array(d["q"]["theta1"]), np.array(d["q"]["theta2"])
    da, db = np.array(d["q_dot"]["theta1"]), np.array(d["q_dot"]["theta2"])
    T = 0.5 * da**2 + 0.5 * (da**2 + db**2 + 2 * da * db * np.cos(a - b))
    V = -2 * G * np.cos(a) - G * np.cos(b)
    return T + V


def _pendulum_energy(d: dict) -> np.ndarray:
    th, w = np.array(d["q"]["theta"]), np.array(d["q_dot"]["theta"])
    return 0.5 * w**2 - G * np.cos(th)


def _run(scene: str, method: str, dt: float, t_end: float) -> dict:
    req = SimulationRequest(method=method, dt=dt, t_end=t_end, check_sensitivity=False)
    return simulate(scene, None, req)


def _energy_warning(d: dict) -> str:
    said = [w for w in d["warnings"] if w.startswith("E ")]
    assert len(said) == 1, d["warnings"]
    return said[0]


def test_explicit_euler_double_pendulum_is_not_called_bounded():
    d = _run("double_pendulum", "euler", 0.05, 10)
    E = _double_pendulum_energy(d)
    t = np.array(d["t"])
    # independently: the per-second floor of E rises by tens of joules (a secular trend)
    floors = [float(E[(t >= s) & (t < s + 1)].min()) for s in range(10)]
    assert floors[0] < 1 and max(floors[5:]) > 20
    said = _energy_warning(d)
    assert "oscillates" not in said and "bounded" not in said
    assert "drifts" in said
    # the double pendulum's M depends on θ1 − θ2: symplectic Euler is no remedy there
    assert "symplectic_euler" not in said


@pytest.mark.parametrize("t_end", [30])
def test_explicit_euler_longer_run_never_bounded(t_end):
    said = _energy_warning(_run("double_pendulum", "euler", 0.05, t_end))
    assert "oscillates" not in said and "bounded" not in said


def test_symplectic_euler_pendulum_is_bounded_and_the_same_at_10_and_100_s():
    short, long = (_run("simple_pendulum", "symplectic_euler", 0.01, te) for te in (10, 100))
    e_short, e_long = _pendulum_energy(short), _pendulum_energy(long)
    # independently: the range at 100 s is the range at 10 s (no growth)
    assert np.ptp(e_long) == pytest.approx(np.ptp(e_short), rel=0.02)
    for d in (short, long):
        said = _energy_warning(d)
        assert "oscillates" in said and "does not grow" in said


def test_symplectic_euler_drifts_on_a_coordinate_dependent_mass_matrix():
    d = _run("double_pendulum", "symplectic_euler", 0.01, 60)
    E = _double_pendulum_energy(d)
    assert E[0] - E.min() > 10  # independently: tens of joules lost, not an oscillation
    said = _energy_warning(d)
    assert "oscillates" not in said and "symplectic method's bounded" not in said
    assert "not symplectic here: the mass matrix changes with the coordinates" in said


def test_explicit_euler_advice_names_symplectic_methods_on_a_constant_mass_matrix():
    d = _run("simple_pendulum", "euler", 0.01, 20)
    E = _pendulum_energy(d)
    assert E[-200:].mean() - E[0] > 1  # independently: grows
    said = _energy_warning(d)
    assert "drifts" in said and "symplectic_euler" in said


def test_descriptions_make_symplecticity_conditional():
    for name in ("symplectic_euler", "implicit_midpoint"):
        text = METHODS[name].description
        assert "mass matrix is constant" in text, text


def test_error_trend_needs_the_same_floor_and_ceiling_in_both_halves():
    t = np.linspace(0, 20, 2001)
    qd = np.sin(3 * t)[None, :]
    swing = np.sin(3 * t)
    assert _error_trend(swing, qd) == "bounded"
    # a floor that rises while the peaks stay (Euler on the double pendulum's shape)
    rising = 30 * (1 - np.exp(-t / 4)) + 30 * np.abs(swing)
    assert _error_trend(rising, qd) != "bounded"
    # a slow trend under a large oscillation: never called bounded
    assert _error_trend(swing + 0.05 * t, qd) != "bounded"


def test_sensitivity_rtols_differ_at_rtol_1e_3():
    req = SimulationRequest(method="RK45", rtol=1e-3, atol=1e-6, t_end=20)
    d = simulate("double_pendulum", None, req)
    pairs = [re.search(r"at rtol (\S+) and (\S+?) ", w) for w in d["warnings"]]
    pairs = [p for p in pairs if p]
    assert pairs, d["warnings"]
    for p in pairs:
        assert float(p.group(1)) != float(p.group(2))


def test_no_symplectic_remedy_is_offered_for_a_damped_oscillator():
    """A damper does work: no energy is conserved, so symplectic Euler has no modified energy
    to keep (work–precision and this warning follow one rule, simulate.why_not_symplectic)."""
    d = _run("spring_mass_damper", "euler", 0.05, 20)
    said = [w for w in d["warnings"] if "drifts" in w or "strays" in w or "reached" in w]
    assert len(said) == 1, d["warnings"]
    assert "symplectic_euler" not in said[0] and "symplectic method" not in said[0]
    # the same advice where the damper and the drive are off: then it is offered
    off = simulate(
        "spring_mass_damper",
        None,
        SimulationRequest(
            method="euler",
            dt=0.05,
            t_end=20,
            check_sensitivity=False,
            parameters={"c": 0.0, "F0": 0.0},
        ),
    )
    assert any("symplectic_euler" in w for w in off["warnings"]), off["warnings"]
