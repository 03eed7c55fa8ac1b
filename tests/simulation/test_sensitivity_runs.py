"""Real runs compared at two tolerances: chaos where it is, a timing drift where it is not.

Independent expectations: the double pendulum's largest Lyapunov exponent, computed here from
the textbook equations of motion (not the engine's) by the classic two-nearby-trajectories
method; for the regular motions, that the two runs differ by a time shift (same shape, other
timing), measured here by sliding one run along the other.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mechanics.divergence import classify_divergence, compare_runs, is_autonomous
from mechanics.integrators import integrate
from mechanics.numeric import compiled_scene, compiled_spec
from mechanics.simulate import SimulationRequest, check_request, simulate

G = 9.81

# A bead on a wire bent into the parabola y = c x², the wire spun about the vertical at Omega:
# one coordinate, a rheonomic constraint, no explicit t in L (the Jacobi integral is conserved).
# With Omega² < 2 g c the bottom is stable and the bead oscillates, its period depending on the
# amplitude (the 4c²x² in T): a regular motion that cannot be chaotic.
PARABOLA = {
    "title": "Bead on a spinning parabola",
    "summary": "A bead on a parabolic wire spun about its axis.",
    "coordinates": ["x"],
    "parameters": {"m": 0.1, "c": 1.0, "Omega": 3.0, "g": G},
    "initial": {"x": 1.0, "x_dot": 0.0},
    "frames": [{"name": "H", "parent": "N", "axis": "y", "angle": "Omega*t"}],
    "bodies": [
        {
            "name": "bead",
            "kind": "particle",
            "mass": "m",
            "position": {"frame": "H", "components": ["x", "c*x**2", 0]},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}


def two_runs(c, req: SimulationRequest):
    """The run as asked and its 1000× looser twin, as the app's sensitivity check makes them."""
    params, y0 = check_request(c, req)
    t_eval = np.linspace(0.0, req.t_end, int(round(req.t_end * req.fps)) + 1)
    loose = min(req.rtol * 1e3, 1e-3)
    runs = [
        integrate(c.rhs(params), y0, t_eval, method=req.method, rtol=r, atol=r, second_order=c.n)
        for r in (req.rtol, loose)
    ]
    assert all(r.status == "ok" for r in runs)
    return params, runs[0], runs[1], (req.rtol, loose)


def double_pendulum_rhs(t, s):
    """Equal masses and lengths (l = 1 m), absolute angles: the textbook equations."""
    th1, th2, w1, w2 = s
    delta = th1 - th2
    den = 3.0 - math.cos(2 * delta)
    a1 = (
        -3 * G * math.sin(th1)
        - G * math.sin(th1 - 2 * th2)
        - 2 * math.sin(delta) * (w2**2 + w1**2 * math.cos(delta))
    ) / den
    a2 = 2 * math.sin(delta) * (2 * w1**2 + 2 * G * math.cos(th1) + w2**2 * math.cos(delta)) / den
    return [w1, w2, a1, a2]


def lyapunov_exponent(y0, t_end=40.0, every=0.5, eps=1e-8) -> float:
    """Benettin: follow a neighbour at distance eps, renormalise every `every` s, average."""
    y, total = np.asarray(y0, float), 0.0
    z = y + np.array([eps, 0, 0, 0])
    for k in range(int(t_end / every)):
        span = (k * every, (k + 1) * every)
        y = solve_ivp(double_pendulum_rhs, span, y, rtol=1e-11, atol=1e-11, method="DOP853").y[
            :, -1
        ]
        z = solve_ivp(double_pendulum_rhs, span, z, rtol=1e-11, atol=1e-11, method="DOP853").y[
            :, -1
        ]
        gap = np.linalg.norm(z - y)
        total += math.log(gap / eps)
        z = y + (z - y) * eps / gap
    return total / t_end


def time_shift_residual(t, a, b, window: float) -> tuple[float, float]:
    """Over the last `window` s: |a − b| as it is, and after the best shift of b in time."""
    last = t >= t[-1] - window
    best = min(
        np.max(np.abs(a[last] - np.interp(t[last] + s, t, b))) for s in np.linspace(-1.0, 1.0, 2001)
    )
    return float(np.max(np.abs(a[last] - b[last]))), float(best)


def test_the_double_pendulum_diverges_exponentially_at_its_lyapunov_rate():
    req = SimulationRequest(t_end=20, check_sensitivity=False)
    tight = simulate(scene_id="double_pendulum", request=req)
    req.rtol = req.atol = 1e-6
    loose = simulate(scene_id="double_pendulum", request=req)
    t = np.array(tight["t"])
    diff = np.abs(np.array(loose["q"]["theta1"]) - np.array(tight["q"]["theta1"]))
    span = float(np.max(np.abs(tight["q"]["theta1"])))
    v = classify_divergence(t, diff, span, n_dof=2, autonomous=True)
    assert v.kind == "exponential" and v.rate > 0
    # the scene's start: 120° and −10° from rest
    lam = lyapunov_exponent([math.radians(120), math.radians(-10), 0.0, 0.0])
    assert lam > 0.3  # measured 0.95 /s
    assert lam / 2 < v.rate < 2 * lam
    assert v.trusted_until is not None and v.trusted_until < 20


def test_the_app_warns_of_chaos_for_the_double_pendulum():
    c = compiled_scene("double_pendulum")
    params, run, loose, tolerances = two_runs(c, SimulationRequest(t_end=20))
    v = compare_runs(c, params, run.t, run.y, loose.y, tolerances)
    assert v.kind == "exponential"
    assert "sensitive" in v.message and "1e-09" in v.message and "0.001" not in v.message


@pytest.mark.parametrize(
    ("t_end", "rtol", "warns"),
    [(20, 1e-9, False), (100, 1e-9, True), (100, 1e-8, True)],
)
def test_a_pendulum_at_170_degrees_drifts_in_phase_and_is_not_called_sensitive(t_end, rtol, warns):
    c = compiled_scene("simple_pendulum")
    req = SimulationRequest(initial={"theta": math.radians(170)}, t_end=t_end, rtol=rtol, atol=rtol)
    params, run, loose, tolerances = two_runs(c, req)
    v = compare_runs(c, params, run.t, run.y, loose.y, tolerances)
    assert v.kind in ("polynomial", "none")
    assert bool(v.message) == warns
    text = v.message.lower()
    assert "sensitive" not in text and "chao" not in text
    if warns:
        assert "phase" in text
    # the data alone (no prior: as if chaos were possible) say the same
    diff = np.abs(loose.y[:, 0] - run.y[:, 0])
    alone = classify_divergence(run.t, diff, float(np.max(np.abs(run.y[:, 0]))), 2, True)
    assert alone.kind in ("polynomial", "none")


def test_the_bead_on_a_spinning_parabola_is_a_timing_drift_with_the_right_shape():
    c = compiled_spec(PARABOLA)
    req = SimulationRequest(t_end=60, rtol=1e-6, atol=1e-6)
    params, run, loose, tolerances = two_runs(c, req)
    assert is_autonomous(c.rhs(params), run.t, run.y)  # spun at constant Omega: no explicit t
    v = compare_runs(c, params, run.t, run.y, loose.y, tolerances)
    assert v.kind == "polynomial"
    text = v.message.lower()
    assert text and "sensitive" not in text and "chao" not in text
    assert "phase" in text and "shape agrees" in text
    # the claim checked: the two runs differ by a time shift, not in shape
    as_is, shifted = time_shift_residual(run.t, run.y[:, 0], loose.y[:, 0], window=10.0)
    assert as_is > 0.3  # out of step by a good part of a period (in metres; x swings ±1 m)
    assert shifted < 0.3 * as_is  # measured 0.11


def test_a_tolerant_run_of_the_parabola_gets_no_warning():
    c = compiled_spec(PARABOLA)
    params, run, loose, tolerances = two_runs(c, SimulationRequest(t_end=20))
    v = compare_runs(c, params, run.t, run.y, loose.y, tolerances)
    assert v.kind in ("polynomial", "none") and v.message == ""


def test_a_driven_oscillator_is_not_autonomous():
    c = compiled_scene("spring_mass_damper")  # pushed by F0 cos(w t)
    params, run, _, _ = two_runs(c, SimulationRequest(t_end=2))
    assert not is_autonomous(c.rhs(params), run.t, run.y)
