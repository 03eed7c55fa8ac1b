"""What the derivation says about E = T + V when the coordinates are measured in a turning frame.

Each expectation comes from equations written here by hand and integrated with solve_ivp: a puck
on a turntable (polar, and Cartesian) keeps E = T + V, so "T + V is not conserved" and "a drive
does work" would be false; a bead on a spinning parabola with friction has Δh = W_NC but
ΔE ≠ W_NC (the motor works too); a bead on a spinning hoop keeps E changing and its sentences.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from independent import own_run
from specs_beyond import turntable_cartesian, turntable_polar

from mechanics.derive import derivation_of_scene, derive_model
from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate

TIGHT = {"rtol": 1e-11, "atol": 1e-12}

# a puck on a frictionless turntable turning at Ω, held by a spring of rest length 0 to the
# centre; (r, φ) measured in the turntable's frame H
TURNTABLE = turntable_polar(positive=True)

# the same puck in Cartesian coordinates of the turning frame: no cyclic coordinate
CARTESIAN = turntable_cartesian()

# a bead on the wire y = a r² spun at Ω about the vertical, with friction against the wire
PARABOLA = {
    "title": "parabola with friction",
    "coordinates": ["r"],
    "parameters": {"m": 0.2, "a": 2.0, "Omega": 5.0, "g": 9.81, "c": 0.3},
    "initial": {"r": 0.1, "r_dot": 0.0},
    "frames": [{"name": "H", "parent": "N", "axis": "y", "angle": "Omega*t"}],
    "bodies": [
        {
            "name": "bead",
            "kind": "particle",
            "mass": "m",
            "position": {"frame": "H", "components": ["r", "a*r**2", 0]},
        }
    ],
    "forces": [
        {
            "name": "friction",
            "on": "bead",
            "vector": {"frame": "H", "components": ["-c*r_dot", "-2*a*c*r*r_dot", 0]},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}


def step(d, step_id):
    return next(s for s in d.steps if s.id == step_id)


def names(d) -> list[str]:
    return [c["name"] for c in d.work.conserved]


def turntable_run(t):
    """Hand-written: r̈ = r (φ̇ + Ω)² − (k/m) r, φ̈ = −2 ṙ (φ̇ + Ω)/r (the puck seen from H)."""
    p, y0 = TURNTABLE["parameters"], TURNTABLE["initial"]
    m, k, Om = p["m"], p["k"], p["Omega"]

    def rhs(_, y):
        r, _phi, rd, phid = y
        return [rd, phid, r * (phid + Om) ** 2 - k / m * r, -2 * rd * (phid + Om) / r]

    sol = own_run(rhs, [y0["r"], y0["phi"], y0["r_dot"], y0["phi_dot"]], t)
    r, _, rd, phid = sol.y
    E = 0.5 * m * (rd**2 + r**2 * (phid + Om) ** 2) + 0.5 * k * r**2  # speed in N, spring
    return sol, E


def test_turntable_puck_keeps_E_and_the_derivation_says_so():
    t = np.linspace(0.0, 20.0, 401)
    _, E = turntable_run(t)
    assert np.ptp(E) < 1e-9 * E[0]  # E = T + V is constant: "not conserved" would be false
    d = derive_model(TURNTABLE)
    text = step(d, "conserved").text
    assert names(d) == ["jacobi", "momentum", "energy"]
    assert "not conserved" not in text and "is conserved too" in text
    assert r"E - h = \Omega p_{\phi}" in text and "does no work" in text
    energy = next(c for c in d.work.conserved if c["name"] == "energy")
    # the listed E at the hand-written E's states
    from mechanics.steps import _symbols_for

    to_sym, _ = _symbols_for(d.model)
    sol, _ = turntable_run(np.array([0.0, 3.0]))
    expr = energy["expr"].xreplace(to_sym)
    params = {d.model.params[n]: v for n, v in TURNTABLE["parameters"].items()}
    for i in range(2):
        state = dict(zip([to_sym[x] for x in (*d.model.q, *d.model.qd)], sol.y[:, i], strict=True))
        assert float(expr.xreplace(state | params)) == pytest.approx(E[0], rel=1e-9)


def test_turntable_coordinates_step_does_not_claim_a_moving_constraint():
    d = derive_model(TURNTABLE)
    s = step(d, "coordinates")
    assert "constraints move" not in s.text and "rheonomic" not in s.text
    assert "turning at a prescribed rate" in s.text
    assert s.data["constraints_move"] is False


def test_turntable_run_is_not_driven_and_keeps_E():
    t_end = 10.0
    result = simulate(scene=TURNTABLE, request=SimulationRequest(t_end=t_end, fps=20, **TIGHT))
    t = np.array(result["t"])
    _, E = turntable_run(t)
    np.testing.assert_allclose(result["energy"]["E"], E, rtol=1e-8)
    assert result["stats"]["driven"] is False  # the drive's work is identically 0
    assert np.max(np.abs(result["energy"]["W_drive"])) < 1e-8 * E[0]
    assert result["stats"]["energy_error"] < 1e-8


def test_cartesian_turntable_puck_keeps_E_by_its_rate():
    """No cyclic coordinate here: E − h = Ω L_z is shown constant by its rate."""
    p, y0 = CARTESIAN["parameters"], CARTESIAN["initial"]
    m, k, Om = p["m"], p["k"], p["Omega"]

    def rhs(_, y):  # ẍ = 2Ω ẏ + Ω² x − (k/m) x, ÿ = −2Ω ẋ + Ω² y − (k/m) y
        x, y_, xd, yd = y
        return [xd, yd, 2 * Om * yd + Om**2 * x - k / m * x, -2 * Om * xd + Om**2 * y_ - k / m * y_]

    sol = own_run(rhs, [y0["x"], y0["y"], y0["x_dot"], y0["y_dot"]], np.linspace(0, 10, 201))
    x, y_, xd, yd = sol.y
    E = 0.5 * m * ((xd - Om * y_) ** 2 + (yd + Om * x) ** 2) + 0.5 * k * (x**2 + y_**2)
    assert np.ptp(E) < 1e-9 * E[0]
    d = derive_model(CARTESIAN)
    text = step(d, "conserved").text
    assert "not conserved" not in text and "energy" in names(d)
    assert "constraints move" not in step(d, "coordinates").text
    result = simulate(scene=CARTESIAN, request=SimulationRequest(t_end=5.0, fps=20))
    assert result["stats"]["driven"] is False


def parabola_run(t):
    """m (1 + 4a²r²) r̈ = m Ω² r − 2 m g a r − 4 m a² r ṙ² − c ṙ (1 + 4a²r²), with
    W_NC = ∫ −c ṙ² (1 + 4a²r²) dt, E = ½ m (ṙ² (1 + 4a²r²) + Ω² r²) + m g a r² (speed in N)
    and h = ½ m (ṙ² (1 + 4a²r²) − Ω² r²) + m g a r²."""
    p = PARABOLA["parameters"]
    m, a, Om, g, c = p["m"], p["a"], p["Omega"], p["g"], p["c"]

    def rhs(_, y):
        r, rd, _ = y
        s = 1 + 4 * a**2 * r**2
        rdd = (m * Om**2 * r - 2 * m * g * a * r - 4 * m * a**2 * r * rd**2 - c * rd * s) / (m * s)
        return [rd, rdd, -c * rd**2 * s]

    y0 = PARABOLA["initial"]
    sol = own_run(rhs, [y0["r"], y0["r_dot"], 0.0], t)
    r, rd, w_nc = sol.y
    s = 1 + 4 * a**2 * r**2
    E = 0.5 * m * (rd**2 * s + Om**2 * r**2) + m * g * a * r**2
    h = 0.5 * m * (rd**2 * s - Om**2 * r**2) + m * g * a * r**2
    return E, h, w_nc


def test_parabola_with_friction_h_changes_by_w_nc_and_E_does_not():
    t = np.linspace(0.0, 3.0, 121)
    E, h, w_nc = parabola_run(t)
    assert abs(w_nc[-1]) > 0.01  # the friction works (−0.014 J)
    np.testing.assert_allclose(h - h[0], w_nc, atol=1e-9)  # Δh = W_NC
    # ΔE ≠ W_NC: the motor works as well (ΔE = −0.064 J)
    assert abs((E[-1] - E[0]) - w_nc[-1]) > 3 * abs(w_nc[-1])
    d = derive_model(PARABOLA)
    text = step(d, "conserved").text
    assert "so $h$ changes by $W^{NC}$" in text
    assert "$E$ changes by $W^{NC}$" not in text
    assert r"W^{NC} + W_{\mathrm{drive}}" in text
    assert step(d, "conserved").data["drive_work"] == "some"
    result = simulate(scene=PARABOLA, request=SimulationRequest(t_end=3.0, fps=40, **TIGHT))
    assert result["stats"]["driven"] is True
    np.testing.assert_allclose(result["energy"]["W_nc"], w_nc, atol=1e-8)
    w_drive = np.array(result["energy"]["W_drive"])
    np.testing.assert_allclose(w_drive, (E - E[0]) - w_nc, atol=1e-8)


def test_bead_on_hoop_keeps_its_sentences_and_its_drive():
    spec = load_scene("bead_on_hoop")
    p = spec["parameters"]
    m, R, Om, g = p["m"], p["R"], p["Omega"], p["g"]
    th0, thd0 = spec["initial"]["theta"], spec["initial"].get("theta_dot", 0.0)

    def bead(_, y):  # θ̈ = sin θ (Ω² cos θ − g/R)
        th, thd = y
        return [thd, np.sin(th) * (Om**2 * np.cos(th) - g / R)]

    th, thd = own_run(bead, [th0, thd0], np.linspace(0.0, 3.0, 121)).y
    E = 0.5 * m * R**2 * (thd**2 + Om**2 * np.sin(th) ** 2) - m * g * R * np.cos(th)
    assert np.ptp(E) > 0.1 * np.max(np.abs(E))  # E really changes: the motor works
    d = derivation_of_scene("bead_on_hoop")
    assert "The constraints move, so $T + V$ is not conserved" in step(d, "conserved").text
    assert "the constraints move (rheonomic)" in step(d, "coordinates").text
    assert names(d) == ["jacobi"]
    result = simulate(scene_id="bead_on_hoop", request=SimulationRequest(t_end=3.0, fps=20))
    assert result["stats"]["driven"] is True
    assert np.max(np.abs(result["energy"]["W_drive"])) > 0.1 * np.max(np.abs(E))


def test_a_plane_turning_about_an_axis_in_it_moves_and_works():
    """The turntable's frame turned about x instead of z: the plane itself turns, so the
    constraint moves and T + V changes (by the hand-written equations, its T has Ω² r² sin²φ)."""
    spec = json.loads(json.dumps(TURNTABLE))
    spec["frames"][0]["axis"] = "x"
    d = derive_model(spec)
    assert "the constraints move (rheonomic)" in step(d, "coordinates").text
    assert "so $T + V$ is not conserved" in step(d, "conserved").text
    assert step(d, "conserved").data["drive_work"] == "some"
