"""Equilibria at a pole of the coordinates in a turning frame, on a positive coordinate's edge,
and past a declared stop (physics play-test 4, findings 1, 2 and 7).

At a pole (r = 0 of polar coordinates, θ = 0 of a sphere) the Coriolis coupling of the radial
motion to the turn about the pole carries a weight r that vanishes there; the linearization in
r alone lost it and called the turntable's origin 'unstable' where it oscillates at
|√(k/m) ± Ω|. The expectations below are closed forms and a linearization built here by hand in
Cartesian coordinates, never the engine's numbers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from specs_beyond import ladder, turntable_cartesian, turntable_polar

from mechanics.derive import derive_model
from mechanics.equilibria import equilibria
from mechanics.numeric import compile_derivation
from mechanics.spec import SpecError
from mechanics.stops import refuse_passed_stops

SPHERE = {
    "title": "spherical pendulum in a turning frame",
    "coordinates": ["theta", "phi"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81, "Omega": 4.0},
    "initial": {"theta": 0.05, "phi": 0.0},
    "frames": [
        {"name": "H", "parent": "N", "axis": "y", "angle": "Omega*t"},
        {"name": "A", "parent": "H", "axis": "y", "angle": "phi"},
        {"name": "B", "parent": "A", "axis": "z", "angle": "theta"},
    ],
    "bodies": [
        {
            "name": "bob",
            "kind": "particle",
            "mass": "m",
            "position": {"frame": "B", "components": [0, "-l", 0]},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}

LADDER = ladder()


def at(out: dict, **q: float) -> dict:
    (e,) = [e for e in out["equilibria"] if all(abs(e["q"][k] - v) < 1e-9 for k, v in q.items())]
    return e


def imaginary_parts(e: dict) -> list[float]:
    return sorted(b for _, b in e["eigenvalues"])


# --- 1. the turntable's origin in polar coordinates ------------------------------------------


@pytest.mark.parametrize("k", [1.0, 4.0])
def test_the_turntable_origin_oscillates_at_the_split_frequencies(k):
    """Seen from the ground the puck is an isotropic oscillator of ω₀ = √(k/m); in the frame
    turning at Ω its two circular modes appear at |ω₀ ± Ω|: 0.5 and 2.5 (k = 1, where K alone
    is negative and only Coriolis holds it), 0.5 and 3.5 (k = 4). Both bounded, as a run from
    r = 0.01 shows; the polar linearization had 'unstable, e^{1.118 t}' and 'ω = 1.323 twice'."""
    m, omega = 1.0, 1.5
    w0 = math.sqrt(k / m)
    expected = sorted([abs(w0 - omega), w0 + omega])
    e = at(equilibria(derive_model(turntable_polar()), {"k": k, "Omega": omega}), r=0.0)
    assert e["kind"] == ("gyroscopically stable" if k < m * omega**2 else "stable")
    assert e["frequencies"] == pytest.approx(expected, rel=1e-9)
    assert imaginary_parts(e) == pytest.approx(
        sorted([-expected[1], -expected[0], expected[0], expected[1]]), rel=1e-9
    )
    assert all(abs(a) < 1e-9 for a, _ in e["eigenvalues"])
    assert "pole" in e["reason"] and "comes twice" not in e["reason"]
    # the engine's Cartesian description of the same puck says the same
    cart = at(equilibria(derive_model(turntable_cartesian()), {"k": k, "Omega": omega}), x=0.0)
    assert cart["kind"] == e["kind"]
    assert cart["frequencies"] == pytest.approx(e["frequencies"], rel=1e-9)


def test_a_damped_turntable_origin_decays_with_the_coriolis_split():
    """Drag −c v relative to the table: in Cartesian coordinates of the turning frame
    m ẍ + (c I + 2mΩ J) ẋ + (k − mΩ²) x = 0 with J = [[0, −1], [1, 0]]; its eigenvalues, from
    numpy here, are the engine's at the polar origin (the damping c r² of φ vanishes there too)."""
    m, k, c, omega = 1.0, 4.0, 0.2, 1.5
    C = c * np.eye(2) + 2 * m * omega * np.array([[0.0, -1.0], [1.0, 0.0]])
    K = (k - m * omega**2) * np.eye(2)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-K / m, -C / m]])
    expected = sorted(np.linalg.eigvals(A), key=lambda z: (z.imag, z.real))
    spec = turntable_polar()
    spec["parameters"]["c"] = c
    spec["forces"] = [
        {
            "name": "drag",
            "on": "puck",
            "vector": {"frame": "P", "components": ["-c*r_dot", "-c*r*phi_dot", 0]},
        }
    ]
    e = at(equilibria(derive_model(spec), {"k": k, "Omega": omega}), r=0.0)
    assert e["kind"] == "asymptotically stable"
    got = sorted((complex(a, b) for a, b in e["eigenvalues"]), key=lambda z: (z.imag, z.real))
    assert np.allclose(got, expected, rtol=1e-7, atol=1e-9)


def _turning_sphere_by_hand(m: float, length: float, g: float, omega: float) -> list[float]:
    """The bob's frequencies about the bottom, from a Lagrangian written here in coordinates
    regular there: X, Z horizontal in the frame H turning at Ω about the vertical y, the bob at
    (X, −√(l² − X² − Z²), Z). v = v_H + Ω ŷ × r; M, C, K of Lagrange's equations at rest at the
    bottom, and numpy's eigenvalues of the first-order system."""
    X, Z, Xd, Zd = sp.symbols("X Z Xd Zd")
    Y = -sp.sqrt(length**2 - X**2 - Z**2)
    r = sp.Matrix([X, Y, Z])
    rd = r.jacobian([X, Z]) * sp.Matrix([Xd, Zd])
    v = rd + sp.Matrix([0, omega, 0]).cross(r)
    lag = sp.Rational(1, 2) * m * v.dot(v) - m * g * Y
    qs, qds = [X, Z], [Xd, Zd]
    p = sp.Matrix([sp.diff(lag, qd) for qd in qds])
    bottom = {X: 0, Z: 0, Xd: 0, Zd: 0}
    M = np.array(p.jacobian(qds).subs(bottom), dtype=float)
    # d/dt ∂L/∂q̇ − ∂L/∂q = 0, linear part: M q̈ + (∂p/∂q − (∂(∂L/∂q)/∂q̇)) q̇ − ∂²L/∂q² q
    dLdq = sp.Matrix([sp.diff(lag, q) for q in qs])
    C = np.array((p.jacobian(qs) - dLdq.jacobian(qds)).subs(bottom), dtype=float)
    K = np.array((-dLdq.jacobian(qs)).subs(bottom), dtype=float)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam = np.linalg.eigvals(A)
    assert np.max(np.abs(lam.real)) < 1e-9
    return sorted(z.imag for z in lam if z.imag > 0)


def test_the_spherical_pendulum_in_a_turning_frame_oscillates_at_its_bottom():
    """Ω = 4 > √(g/l): the centrifugal term makes K negative at the bottom, Coriolis holds it;
    the frequencies are 0.868 and 7.132 (|√(g/l) ± Ω|), where θ alone said 'unstable, 2.488'."""
    p = SPHERE["parameters"]
    expected = _turning_sphere_by_hand(p["m"], p["l"], p["g"], p["Omega"])
    w0 = math.sqrt(p["g"] / p["l"])
    assert expected == pytest.approx([p["Omega"] - w0, p["Omega"] + w0], rel=1e-9)
    out = equilibria(derive_model(SPHERE), {})
    bottom = at(out, theta=0.0)
    assert bottom["kind"] == "gyroscopically stable"
    assert bottom["frequencies"] == pytest.approx(expected, rel=1e-7)
    assert bottom["frequencies"] == pytest.approx([0.87, 7.13], abs=5e-3)
    # slower than the Coriolis coupling: Ω = 1 < √(g/l), K positive, still split by Ω
    slow = at(equilibria(derive_model(SPHERE), {"Omega": 1.0}), theta=0.0)
    assert slow["kind"] == "stable"
    assert slow["frequencies"] == pytest.approx(
        _turning_sphere_by_hand(p["m"], p["l"], p["g"], 1.0), rel=1e-7
    )


def test_the_top_of_the_turning_sphere_falls_and_turns():
    """Inverted, the bob falls as e^{√(g/l) t} seen from the ground; in the turning frame every
    eigenvalue also carries ±iΩ: λ = ±√(g/l) ± iΩ, four of them (θ alone had ±√(g/l) twice)."""
    p = SPHERE["parameters"]
    w0 = math.sqrt(p["g"] / p["l"])
    top = at(equilibria(derive_model(SPHERE), {}), theta=math.pi)
    assert top["kind"] == "unstable"
    assert sorted(abs(a) for a, _ in top["eigenvalues"]) == pytest.approx([w0] * 4, rel=1e-7)
    assert sorted(abs(b) for _, b in top["eigenvalues"]) == pytest.approx(
        [p["Omega"]] * 4, rel=1e-7
    )


# --- 2. a declared-positive coordinate's edge is not listed ----------------------------------


def test_a_family_along_a_positive_coordinate_is_shown_inside_it():
    """k = mΩ²: no force at rest, every r is an equilibrium; r is declared positive, so r = 0 is
    not a state of the scene. The member shown lies inside (r > 0), where M = m diag(1, r²),
    K = 0 and Coriolis C_rφ = −2mΩr, C_φr = 2mΩr give λ⁴ + 4Ω²λ² = 0: λ = 0, 0, ±2iΩ (the
    Cartesian spec's 'bounded loop, λ = 0, 0, ±4i' at Ω = 2)."""
    omega = 1.5
    out = equilibria(derive_model(turntable_polar(positive=True)), {"k": 2.25, "Omega": omega})
    assert out["equilibria"], out["warnings"]
    assert all(e["q"]["r"] > 0 for e in out["equilibria"])
    (e,) = out["equilibria"]
    assert imaginary_parts(e) == pytest.approx([-2 * omega, 0.0, 0.0, 2 * omega], abs=1e-9)
    assert any("r is declared positive" in w for w in out["warnings"])
    # k = 1: the origin is the only balance, on the excluded edge: not listed (as before)
    out = equilibria(derive_model(turntable_polar(positive=True)), {"k": 1.0, "Omega": omega})
    assert out["equilibria"] == []


# --- 7. an equilibrium past a declared stop is left out --------------------------------------


def test_the_ladder_hanging_through_the_floor_is_left_out():
    """Frictionless ladder against a wall: at rest at θ the wall pushes with
    N_w = m ẍ_G = (3mg/4) sin θ cos θ, which is < 0 for π/2 < θ < π (the wall would have to
    pull) and 0 at θ = π, the ladder hanging through the floor: the stop 'wall_contact' says the
    model does not hold there, and /simulate refuses to start there. θ = π was listed 'stable,
    ω = 2.712' with a 'start near' button."""
    d = derive_model(LADDER)
    out = equilibria(d, {})
    listed = [e["q"]["theta"] for e in out["equilibria"]]
    assert all(abs(abs(x) - math.pi) > 1e-6 for x in listed), listed
    assert any("wall_contact" in w and "left out" in w for w in out["warnings"])
    m, g = LADDER["parameters"]["m"], LADDER["parameters"]["g"]
    for theta in (math.pi / 2 + 1e-3, math.pi - 1e-3):
        assert 0.75 * m * g * math.sin(theta) * math.cos(theta) < 0
    # the upright ladder, where the wall force is 0 and the model holds, stays listed
    assert any(abs(x) < 1e-9 for x in listed)
    # and /simulate's own check refuses θ = π, as the panel now says
    c = compile_derivation(d)
    params = [LADDER["parameters"][k] for k in c.parameters]
    with pytest.raises(SpecError, match="does not hold"):
        refuse_passed_stops(c, params, np.array([math.pi, 0.0, *[0.0] * c.extras]))
