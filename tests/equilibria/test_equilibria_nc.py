"""Stability claims where non-conservative forces act, and at a pole of Euler angles.

Lagrange–Dirichlet ('a minimum of V is stable') holds only while the velocity-dependent forces
do no positive work; a follower load makes K non-symmetric, so no potential stands behind it;
and Euler angles are singular at θ = 0 for every parameter value. Every expectation is derived
here by hand: the power Σ Q_j q̇_j of each force, the eigenvalues of M, C, K written out and
given to numpy, an independent scipy integration of the energy, sympy's LagrangesMethod for the
heavy top, and the compound pendulum's ω² = m g h/(I₁ + m h²).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.integrate
import sympy as sp
from independent import engine_eigenvalues, first_order_eigenvalues
from sympy.physics.mechanics import (
    LagrangesMethod,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
)

from mechanics.derive import derive_model
from mechanics.equilibria import equilibria


def solve(spec: dict, **parameters) -> dict:
    return equilibria(derive_model(spec), parameters)


def only(result: dict) -> dict:
    assert len(result["equilibria"]) == 1, [e["q"] for e in result["equilibria"]]
    return result["equilibria"][0]


# --- 1. a force whose power has no sign --------------------------------------------------------


def cubic(c: float) -> dict:
    """The play-tester's particle: a spring k = 4 from O along x, and F = c ẋ³ x̂."""
    return {
        "title": "Cubic force",
        "coordinates": ["x"],
        "parameters": {"m": 1.0, "k": 4.0, "c": c},
        "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
        "springs": [{"name": "s", "a": "O", "b": "b", "k": "k"}],
        "forces": [{"name": "f", "on": "b", "vector": ["c*x_dot**3", 0, 0]}],
    }


def energy_after(c: float, t_end: float = 40.0) -> float:
    """E = ẋ²/2 + 2x² at t_end from x = 0.3 at rest, for ẍ = −4x + c ẋ³ (m = 1), by scipy."""
    sol = scipy.integrate.solve_ivp(
        lambda t, y: [y[1], -4 * y[0] + c * y[1] ** 3],
        (0, t_end),
        [0.3, 0.0],
        rtol=1e-10,
        atol=1e-12,
    )
    x, v = sol.y[:, -1]
    return v**2 / 2 + 2 * x**2


def test_a_force_that_pumps_energy_in_is_not_called_stable():
    """Its power is F ẋ = c ẋ⁴ ≥ 0: E grows (scipy shows it), though K = 4 > 0 and the
    linearization, which cannot see an ẋ³, has λ = ±2i. The honest verdict is 'marginal'.
    With c < 0 the power is ≤ 0, E decays, and the minimum of V holds: stable (no false
    alarm)."""
    assert energy_after(0.1) > 1.5 * energy_after(0.0)  # the fact: energy is pumped in
    e = only(solve(cubic(0.1)))
    assert e["kind"] == "marginal" and not e["stable"], e["reason"]
    # P = c ẋ⁴ is never negative: said so, not "has no sign" (physics play-test)
    assert "is never negative: they feed energy in" in e["reason"], e["reason"]
    assert r"\sum_j Q_j^{NC} \dot q_j = c \dot{x}^{4}" in e["reason"]
    assert engine_eigenvalues(e) == pytest.approx(first_order_eigenvalues([[1]], [[0]], [[4]]))

    assert energy_after(-0.1) < energy_after(0.0)
    e = only(solve(cubic(-0.1)))
    assert e["kind"] == "stable", e["reason"]


def trap(vector: list, **parameters) -> dict:
    """A particle in the isotropic trap V = k (x² + y²)/2, with one force."""
    return {
        "title": "Trapped particle",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "k": 4.0, "c": 0.1, "q": 1.0, "B": 0.5, **parameters},
        "bodies": [{"name": "p", "mass": "m", "position": ["x", "y", 0]}],
        "potentials": [{"name": "trap", "expression": "k*(x**2 + y**2)/2"}],
        "forces": [{"name": "f", "on": "p", "vector": vector}],
    }


def test_a_negative_power_plus_a_term_that_can_win_is_not_stable():
    """F = (−c ẋ + c ẋ²) x̂: power c ẋ²(ẋ − 1), positive once ẋ > 1; and the y mode is
    undamped, so the linearization (λ = ±2i there) cannot decide. Whereas F = −c (ẋ − ẏ)(1, −1)
    has power −c (ẋ − ẏ)² ≤ 0, though written out it has a cross term: with its (1, 1) mode
    undamped only the energy argument decides, and it says stable (no false alarm)."""
    e = only(solve(trap(["-c*x_dot + c*x_dot**2", 0, 0])))
    assert e["kind"] == "marginal", e["reason"]
    C = 0.1 * np.array([[1, 0], [0, 0]])
    assert engine_eigenvalues(e) == pytest.approx(
        first_order_eigenvalues(np.eye(2), C, 4 * np.eye(2))
    )

    e = only(solve(trap(["-c*(x_dot - y_dot)", "c*(x_dot - y_dot)", 0])))
    assert e["kind"] == "stable", e["reason"]
    C = 0.1 * np.array([[1, -1], [-1, 1]])
    assert engine_eigenvalues(e) == pytest.approx(
        first_order_eigenvalues(np.eye(2), C, 4 * np.eye(2))
    )


@pytest.mark.parametrize(("k", "B", "kind"), [(1.0, 0.5, "stable"), (-1.0, 3.0, None)])
def test_a_magnetic_force_is_gyroscopic_not_coriolis(k, B, kind):
    """The Lorentz force q B (ẏ, −ẋ) has power q B (ẏ ẋ − ẋ ẏ) = 0: a trap's minimum stays
    stable; with an anti-trap (k < 0) and B² > 4|k| the gyroscopic terms hold it linearly. No
    frame turns: nothing here is a Coriolis term."""
    e = only(solve(trap(["q*B*y_dot", "-q*B*x_dot", 0], k=k, B=B)))
    C = np.array([[0.0, -B], [B, 0.0]])
    expected = first_order_eigenvalues(np.eye(2), C, k * np.eye(2))
    assert engine_eigenvalues(e) == pytest.approx(expected)
    assert np.max(expected.real) <= 1e-9  # B² > 4|k|: every λ on the imaginary axis
    assert e["kind"] == (kind or "gyroscopically stable"), e["reason"]
    assert "Coriolis" not in e["reason"] and "do no work" in e["reason"]


def test_a_velocity_force_that_varies_in_time_is_undecided_not_an_error():
    """C = c cos t: the linearization changes with t, and no one instant's eigenvalues decide."""
    e = only(solve(trap(["-c*x_dot*cos(t)", 0, 0])))
    assert e["kind"] == "marginal" and "time" in e["reason"]


# --- 2. a follower load (circulatory forces) -------------------------------------------------


def ziegler(P: float) -> dict:
    """Ziegler's pendulum: 2m at the joint, m at the tip, rotational springs k on both joints,
    and a follower force P along the second rod, pointing back down it."""
    return {
        "title": "Ziegler pendulum",
        "coordinates": ["a", "b"],
        "parameters": {"m": 1.0, "l": 1.0, "k": 1.0, "P": P},
        "units": {"a": "rad", "b": "rad", "l": "m", "k": "N*m", "P": "N"},
        "bodies": [
            {"name": "j", "mass": "2*m", "position": ["l*sin(a)", "l*cos(a)", 0]},
            {
                "name": "tip",
                "mass": "m",
                "position": {"frame": "N", "components": ["l*sin(b)", "l*cos(b)", 0], "from": "j"},
            },
        ],
        "potentials": [{"name": "springs", "expression": "k*a**2/2 + k*(b - a)**2/2"}],
        "forces": [{"name": "follower", "on": "tip", "vector": ["-P*sin(b)", "-P*cos(b)", 0]}],
    }


def ziegler_mk(P: float) -> tuple[np.ndarray, np.ndarray]:
    """By hand (m = l = k = 1): T = ½(3ȧ² + 2ȧḃ cos(a − b) + ḃ²), so M = [[3, 1], [1, 1]] at
    rest; Q_a = F·∂r_tip/∂a = −P sin(b − a), Q_b = 0; V_a = 2a − b, V_b = b − a. Hence
    K = [[2 − P, P − 1], [−1, 1]], det K = 1 for every P, never symmetric for P ≠ 0."""
    return np.array([[3.0, 1.0], [1.0, 1.0]]), np.array([[2 - P, P - 1], [-1.0, 1.0]])


@pytest.mark.parametrize("P", [1.0, 2.0, 2.2, 3.0])
def test_follower_load_is_judged_by_the_eigenvalues_not_a_potential(P):
    """K's eigenvalues say nothing of a minimum (at P = 2.2 they are 0.4 ± 0.917i, and
    det K = 1 for every P): the verdict and its reason come from the first-order eigenvalues,
    marginal while they sit on the imaginary axis, flutter once a complex pair crosses."""
    M, K = ziegler_mk(P)
    expected = first_order_eigenvalues(M, np.zeros((2, 2)), K)
    assert np.linalg.det(K) == pytest.approx(1.0)
    if P == 2.2:
        k_eigs = np.linalg.eigvals(K)
        assert k_eigs.real == pytest.approx([0.4, 0.4]) and abs(k_eigs[0].imag) > 0.9
    e = only(solve(ziegler(P)))
    assert e["q"] == pytest.approx({"a": 0.0, "b": 0.0}, abs=1e-9)
    assert engine_eigenvalues(e) == pytest.approx(expected, abs=1e-7)
    assert "not symmetric" in e["reason"] and "circulatory" in e["reason"]
    for false in ("no minimum", "negative eigenvalue", "singular", "positive definite"):
        assert false not in e["reason"], e["reason"]
    if np.max(expected.real) > 1e-9:  # P = 2.2, 3: a complex pair grows (flutter)
        assert np.all(np.abs(expected.imag) > 0.1)
        assert e["kind"] == "unstable" and "flutter" in e["reason"]
    else:
        assert e["kind"] == "marginal", e["reason"]


# --- 4. the heavy symmetric top at the pole of its Euler angles -------------------------------


def top(**parameters) -> dict:
    """Euler angles y–x–y: A = N about y by φ, B = A about x by θ, C = B about y by ψ; the
    centre of mass at h along C.y from the fixed tip O; gravity along −N.y."""
    return {
        "title": "Heavy symmetric top",
        "coordinates": ["phi", "th", "psi"],
        "parameters": {"m": 1.0, "h": 1.0, "g": 1.0, "I1": 1.0, "I3": 1.0, **parameters},
        "units": {"phi": "rad", "th": "rad", "psi": "rad"},
        "frames": [
            {"name": "A", "parent": "N", "axis": "y", "angle": "phi"},
            {"name": "B", "parent": "A", "axis": "x", "angle": "th"},
            {"name": "C", "parent": "B", "axis": "y", "angle": "psi"},
        ],
        "bodies": [
            {
                "name": "top",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "C",
                "position": {"frame": "C", "components": [0, "h", 0]},
                "inertia": {"ixx": "I1", "iyy": "I3", "izz": "I1"},
            }
        ],
        "gravity": {"acceleration": "g"},
    }


def top_by_lagranges_method() -> tuple[sp.Matrix, sp.Matrix, list, list, tuple]:
    """M and the forcing from sympy's own LagrangesMethod, built here from the same frames."""
    phi, th, psi = q = dynamicsymbols("phi th psi")
    m, h, g, I1, I3 = params = sp.symbols("m h g I1 I3", positive=True)
    N = ReferenceFrame("N")
    A, B, C = ReferenceFrame("A"), ReferenceFrame("B"), ReferenceFrame("C")
    A.orient_axis(N, N.y, phi)
    B.orient_axis(A, A.x, th)
    C.orient_axis(B, B.y, psi)
    O = Point("O")  # noqa: E741 — the fixed tip
    O.set_vel(N, 0)
    G = O.locatenew("G", h * C.y)
    G.v2pt_theory(O, N, C)
    body = RigidBody("top", G, C, m, (inertia(C, I1, I3, I1), G))
    body.potential_energy = m * g * G.pos_from(O).dot(N.y)
    L = sp.simplify(body.kinetic_energy(N) - body.potential_energy)
    lm = LagrangesMethod(L, q)
    lm.form_lagranges_equations()
    return lm.mass_matrix, lm.forcing, list(q), [x.diff() for x in q], params


@pytest.mark.parametrize(
    "parameters",
    [
        {},
        {"m": 1.0, "h": 0.3, "g": 9.81, "I1": 0.02, "I3": 0.04},
    ],
)
def test_the_top_at_rest_falls_upright_and_swings_hanging(parameters):
    """Upright (θ = 0) and hanging (θ = π) are both at the pole. Near θ = π the top is a
    compound pendulum about its tip in any vertical plane: ω² = m g h/(I₁ + m h²), twice;
    upright it falls in any plane at the rate √(m g h/(I₁ + m h²)). The same ω² comes out of
    LagrangesMethod's own equations (the θ equation: −∂f_θ/∂θ over M_θθ at θ = π), whose
    det M = I₃ (I₁ + m h²)² sin²θ vanishes at both for every parameter value: a pole of the
    coordinates, not a choice of units."""
    p = {"m": 1.0, "h": 1.0, "g": 1.0, "I1": 1.0, "I3": 1.0, **parameters}
    omega2 = p["m"] * p["g"] * p["h"] / (p["I1"] + p["m"] * p["h"] ** 2)
    M, f, q, qd, symbols = top_by_lagranges_method()
    m, h, _, I1, I3 = symbols
    assert sp.simplify(M.det() - I3 * (I1 + m * h**2) ** 2 * sp.sin(q[1]) ** 2) == 0
    values = dict(zip(symbols, (p[k] for k in ("m", "h", "g", "I1", "I3")), strict=True))
    rest = dict.fromkeys(qd, 0)
    k_th = -sp.diff(f[1].subs(rest), q[1]).subs(values).subs({q[1]: sp.pi})
    assert float(k_th / M[1, 1].subs(values)) == pytest.approx(omega2)

    result = solve(top(**parameters))
    thetas = sorted(abs(e["q"]["th"]) for e in result["equilibria"])
    assert thetas == pytest.approx([0.0, math.pi])
    for e in result["equilibria"]:
        assert "pole of the coordinates" in e["reason"]
        hanging = abs(e["q"]["th"]) > 1
        if hanging:
            assert e["kind"] == "marginal" and not e["stable"], e[
                "reason"
            ]  # free φ drifts: neutral (issue 25)
            assert e["frequencies"] == pytest.approx([math.sqrt(omega2)] * 2, rel=1e-9)
        else:
            assert e["kind"] == "unstable"
            growth = sorted(z[0] for z in e["eigenvalues"])[-2:]
            assert growth == pytest.approx([math.sqrt(omega2)] * 2, rel=1e-9)


def test_a_top_with_its_centre_of_mass_off_the_axis_rests_only_with_it_plumb_below_or_above():
    """Euler angles z–x–z, gravity along −z, the centre of mass at (a, 0, h) in the body. At
    θ = 0 every Q_j vanishes (the coordinates cannot turn about the axis they lose there), yet
    gravity's torque m g a acts: no equilibrium. The true ones put G plumb below or above O,
    at height z_G = h cos θ + a sin θ sin ψ = ∓d, d = √(a² + h²). Hanging, it swings as a
    compound pendulum about O: about the body's y axis (⊥ OG) with I = I₁ + m d²; about
    u = (h, 0, −a)/d with I_uu = (I₁h² + I₃a²)/d² + m d², lessened by its product of inertia
    with the free spin about the vertical w = (a, 0, h)/d: I_uw = a h (I₁ − I₃)/d²,
    I_ww = (I₁a² + I₃h²)/d², so I_eff = I_uu − I_uw²/I_ww. ω² = m g d/I for each."""
    m, h, g, I1, I3, a = 1.0, 1.0, 1.0, 1.0, 0.5, 0.3
    spec = top(I3=I3)
    spec["parameters"]["a"] = a
    spec["frames"] = [
        {"name": "A", "parent": "N", "axis": "z", "angle": "phi"},
        {"name": "B", "parent": "A", "axis": "x", "angle": "th"},
        {"name": "C", "parent": "B", "axis": "z", "angle": "psi"},
    ]
    spec["bodies"][0]["position"] = {"frame": "C", "components": ["a", 0, "h"]}
    spec["bodies"][0]["inertia"] = {"ixx": "I1", "iyy": "I1", "izz": "I3"}
    spec["gravity"] = {"acceleration": "g", "direction": [0, 0, -1]}
    result = solve(spec)
    d = math.hypot(a, h)
    assert result["equilibria"]
    for e in result["equilibria"]:
        th, psi = e["q"]["th"], e["q"]["psi"]
        z = h * math.cos(th) + a * math.sin(th) * math.sin(psi)
        assert abs(z) == pytest.approx(d, rel=1e-9), e["q"]  # plumb: none at θ = 0
        if z < 0:
            I_uu = (I1 * h**2 + I3 * a**2) / d**2 + m * d**2
            I_uw, I_ww = a * h * (I1 - I3) / d**2, (I1 * a**2 + I3 * h**2) / d**2
            inertias = [I1 + m * d**2, I_uu - I_uw**2 / I_ww]
            expected = sorted(math.sqrt(m * g * d / i) for i in inertias)
            assert e["kind"] == "marginal"  # free φ drifts: neutral (issue 25)
            assert e["frequencies"] == pytest.approx(expected)
        else:
            assert e["kind"] == "unstable"
    assert any("pole of the coordinates" in w for w in result["warnings"])


def test_a_spherical_pendulum_in_a_wind_does_not_rest_at_its_pole():
    """A constant wind F x̂ on the bob: at θ = 0 with φ = ±π/2 both Q_θ = F l cos θ cos φ and
    Q_φ = −F l sin θ sin φ vanish, but the wind still pushes the bob sideways. It rests only
    where the string lines up with m g + F: tan θ = F/(m g) hanging, and the opposite way up."""
    from mechanics.scenes import load_scene

    spec = load_scene("spherical_pendulum")
    spec["parameters"]["F"] = 2.0
    spec["forces"] = [{"name": "wind", "on": spec["bodies"][0]["name"], "vector": ["F", 0, 0]}]
    p = spec["parameters"]
    result = solve(spec)
    tilt = math.atan2(p["F"], p["m"] * p["g"])
    thetas = sorted(abs(e["q"]["theta"]) for e in result["equilibria"])
    assert thetas == pytest.approx([tilt, math.pi - tilt])
