"""Equilibria beyond the closed forms K alone gives: velocity-linear terms (turntables, damping),
roots sp.solve drops, duplicates, angles in posted specs without units, springs past their anchor.

Every expected value is independent of the engine: a closed form, the eigenvalues of M, C, K
written out by hand here, sympy's LagrangesMethod, or this file's own numeric root search.
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
import pytest
import scipy.optimize
import sympy as sp
from independent import engine_eigenvalues, first_order_eigenvalues
from sympy.physics.mechanics import LagrangesMethod, Particle, Point, ReferenceFrame, dynamicsymbols

from mechanics.derive import derivation_of_scene, derive_model
from mechanics.equilibria import equilibria

G = 9.81


def solve(spec: dict, **parameters) -> dict:
    return equilibria(derive_model(spec), parameters)


def at(result: dict, **q) -> dict:
    for e in result["equilibria"]:
        if all(math.isclose(e["q"][k], v, abs_tol=1e-7) for k, v in q.items()):
            return e
    raise AssertionError(f"no equilibrium at {q}: {[e['q'] for e in result['equilibria']]}")


def turntable(omega: float, k: float = 4.0, m: float = 1.0) -> dict:
    """A particle at (x, y) in a frame turning at Omega about z, on a spring to the axis."""
    return {
        "coordinates": ["x", "y"],
        "parameters": {"m": m, "k": k, "Omega": omega},
        "frames": [{"name": "F", "parent": "N", "axis": "z", "angle": "Omega*t"}],
        "points": [{"name": "anchor", "position": [0, 0, 0]}],
        "bodies": [
            {"name": "p", "mass": "m", "position": {"frame": "F", "components": ["x", "y", 0]}}
        ],
        "springs": [{"a": "anchor", "b": "p", "k": "k"}],
    }


def anisotropic_turntable(omega: float, kx: float, ky: float) -> dict:
    spec = turntable(omega)
    del spec["springs"], spec["points"]
    spec["parameters"] = {"m": 1.0, "kx": kx, "ky": ky, "Omega": omega}
    spec["potentials"] = [{"name": "springs", "expression": "kx*x**2/2 + ky*y**2/2"}]
    return spec


def turntable_mck(omega: float, kx: float, ky: float, m: float = 1.0):
    """By hand: m(ẍ − 2Ωẏ − Ω²x) = −kx x, m(ÿ + 2Ωẋ − Ω²y) = −ky y."""
    M = m * np.eye(2)
    C = np.array([[0.0, -2 * m * omega], [2 * m * omega, 0.0]])
    K = np.diag([kx - m * omega**2, ky - m * omega**2])
    return M, C, K


# --- velocity-linear terms: the turntable ----------------------------------------------------


def test_turntable_frequencies_are_root_k_over_m_plus_and_minus_omega():
    """Isotropic spring seen from the turning frame: z = x + iy obeys z̈ + 2iΩż + (ω₀² − Ω²)z = 0,
    λ = −iΩ ± iω₀: the frequencies are |ω₀ ± Ω| (not √(ω₀² − Ω²) twice, which K alone says)."""
    r = solve(turntable(1.5))
    (e,) = r["equilibria"]
    assert e["frequencies"] == pytest.approx([0.5, 3.5], rel=1e-9)
    assert e["kind"] == "stable" and e["stable"]
    assert "positive definite" in e["reason"]
    np.testing.assert_allclose(
        engine_eigenvalues(e), first_order_eigenvalues(*turntable_mck(1.5, 4, 4))
    )
    # a whirl, not a standing pattern: x and y a quarter period apart
    for phases in e["mode_phases"]:
        assert sorted(abs(p) for p in phases) == pytest.approx([0.0, math.pi / 2])


def test_turntable_spun_fast_is_gyroscopically_stable_with_eigenvalues_i_and_5i():
    r = solve(turntable(3.0))
    (e,) = r["equilibria"]
    assert e["kind"] == "gyroscopically stable" and e["stable"]
    assert sorted(abs(b) for a, b in e["eigenvalues"]) == pytest.approx([1, 1, 5, 5])
    assert all(abs(a) < 1e-9 for a, b in e["eigenvalues"])
    assert e["frequencies"] == pytest.approx([1.0, 5.0])
    assert "not positive definite" in e["reason"] and "damping" in e["reason"]
    (line,) = [p for p in r["steps"][1]["plain"] if p.startswith("x = 0, y = 0:")]
    assert "gyroscopically stable" in line and "because" in line


def test_turntable_at_omega_equal_root_k_over_m_is_marginal():
    """Ω = ω₀: K = 0 (no restoring force in the turning frame, every point balances), λ = 0
    twice: undecided."""
    e = at(solve(turntable(2.0)), x=0.0, y=0.0)
    assert e["kind"] == "marginal" and not e["stable"]
    assert "singular" in e["reason"]


def test_turntable_against_sympy_lagranges_method():
    """M, C, K from sympy's own LagrangesMethod on the same particle, then their eigenvalues."""
    x, y = dynamicsymbols("x y")
    xd, yd = dynamicsymbols("x y", 1)
    m, k, omega, tt = sp.symbols("m k Omega t")
    N = ReferenceFrame("N")
    F = N.orientnew("F", "Axis", [omega * tt, N.z])
    origin = Point("O")
    origin.set_vel(N, 0)
    P = origin.locatenew("P", x * F.x + y * F.y)
    P.set_vel(N, P.pos_from(origin).dt(N))
    p = Particle("p", P, m)
    p.potential_energy = k * (x**2 + y**2) / 2
    L = sp.physics.mechanics.Lagrangian(N, p)
    lm = LagrangesMethod(L, [x, y], frame=N)
    lm.form_lagranges_equations()
    rest = {xd.diff(): 0, yd.diff(): 0, xd: 0, yd: 0, x: 0, y: 0}
    values = {m: 1.0, k: 4.0, omega: 1.5}
    forcing = lm.forcing
    M = np.array(lm.mass_matrix.subs(values), dtype=float)
    K = -np.array(forcing.jacobian([x, y]).subs(rest).subs(values), dtype=float)
    C = -np.array(forcing.jacobian([xd, yd]).subs(rest).subs(values), dtype=float)
    (e,) = solve(turntable(1.5))["equilibria"]
    np.testing.assert_allclose(engine_eigenvalues(e), first_order_eigenvalues(M, C, K), atol=1e-8)


@pytest.mark.parametrize(
    "omega, kind",
    [(1.0, "stable"), (2.5, "unstable"), (4.0, "gyroscopically stable")],
)
def test_anisotropic_turntable_is_unstable_only_between_the_two_spring_frequencies(omega, kind):
    """kx/m = 4, ky/m = 9: (λ² + a)(λ² + b) + 4Ω²λ² = 0 with a = 4 − Ω², b = 9 − Ω² has a root
    with Re λ > 0 exactly when ab < 0, i.e. 2 < Ω < 3; above 3 both are negative (K negative
    definite) and Coriolis holds it. (The isotropic turntable has no such window: λ = −iΩ ± iω₀.)"""
    (e,) = solve(anisotropic_turntable(omega, 4.0, 9.0))["equilibria"]
    expected = first_order_eigenvalues(*turntable_mck(omega, 4.0, 9.0))
    np.testing.assert_allclose(engine_eigenvalues(e), expected, atol=1e-8)
    assert e["kind"] == kind
    assert e["stable"] == (kind != "unstable")
    if kind != "unstable":
        assert e["frequencies"] == pytest.approx(sorted(abs(z.imag) for z in expected)[::2])


def test_damped_oscillator_is_asymptotically_stable_with_the_damped_frequency():
    m, k, c = 1.0, 10.0, 0.4
    r = equilibria(derivation_of_scene("spring_mass_damper"), {"F0": 0.0, "m": m, "k": k, "c": c})
    e = at(r, x=0.0)
    assert e["kind"] == "asymptotically stable" and e["stable"]
    np.testing.assert_allclose(engine_eigenvalues(e), np.sort_complex(np.roots([m, c, k])))
    assert e["frequencies"] == pytest.approx([math.sqrt(k / m - (c / (2 * m)) ** 2)])


def test_inverted_pendulum_is_unstable_with_growth_rate_root_g_over_l():
    length = 2.0
    r = equilibria(derivation_of_scene("simple_pendulum"), {"g": G, "l": length})
    up = at(r, theta=math.pi)
    assert up["kind"] == "unstable" and not up["stable"] and up["frequencies"] == []
    assert max(a for a, b in up["eigenvalues"]) == pytest.approx(math.sqrt(G / length))
    assert "positive real part" in up["reason"]
    assert at(r, theta=0.0)["kind"] == "stable"


# --- every root, once, wrapped ---------------------------------------------------------------


def rod_on_turntable(omega: float) -> dict:
    return {
        "coordinates": ["theta"],
        "parameters": {"m": 1.0, "L": 1.0, "g": G, "Omega": omega},
        "frames": [
            {"name": "H", "parent": "N", "axis": "y", "angle": "Omega*t"},
            {"name": "R", "parent": "H", "axis": "z", "angle": "theta"},
        ],
        "bodies": [
            {
                "name": "rod",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "R",
                "position": {"frame": "R", "components": [0, "-L/2", 0]},
                "inertia": {"ixx": "m*L**2/12", "iyy": 0, "izz": "m*L**2/12"},
            }
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }


@pytest.mark.parametrize("omega", [6.0, 2.0])
def test_rod_on_turntable_has_both_ends_and_the_off_axis_pair_above_critical_spin(omega):
    """I_O = mL²/3: (mL²/3)Ω² sinθ cosθ = (mgL/2) sinθ, so θ = 0, π and, when
    c = 3g/(2LΩ²) ≤ 1, θ = ±acos c with ω² = Ω²(1 − c²)."""
    r = solve(rod_on_turntable(omega))
    c = 3 * G / (2 * omega**2)
    expected = [0.0, math.pi] + ([math.acos(c), -math.acos(c)] if c <= 1 else [])
    assert sorted(e["q"]["theta"] for e in r["equilibria"]) == pytest.approx(sorted(expected))
    assert at(r, theta=math.pi)["kind"] == "unstable"
    if c <= 1:
        assert not at(r, theta=0.0)["stable"]
        for sign in (1, -1):
            e = at(r, theta=sign * math.acos(c))
            assert e["kind"] == "stable"
            assert e["frequencies"] == pytest.approx([omega * math.sqrt(1 - c**2)], rel=1e-9)
    else:
        w2 = 3 * G / (2 * 1.0) - omega**2  # at θ = 0: ω² = 3g/(2L) − Ω²
        assert at(r, theta=0.0)["frequencies"] == pytest.approx([math.sqrt(w2)])


def hoop() -> dict:
    """The bead on a spinning hoop as a course tool would post it: no units at all."""
    return {
        "coordinates": ["theta"],
        "parameters": {"m": 0.1, "R": 0.5, "Omega": 6.0, "g": G},
        "frames": [{"name": "H", "parent": "N", "axis": "y", "angle": "Omega*t"}],
        "bodies": [
            {
                "name": "bead",
                "mass": "m",
                "position": {"frame": "H", "components": ["R*sin(theta)", "-R*cos(theta)", 0]},
            }
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }


def test_posted_hoop_without_units_has_its_angles_wrapped():
    r = solve(hoop())
    theta0 = math.acos(G / (0.5 * 36.0))
    got = sorted(e["q"]["theta"] for e in r["equilibria"])
    assert got == pytest.approx(sorted([0.0, math.pi, theta0, -theta0]))
    assert all(-math.pi < v <= math.pi for v in got)
    assert "2*pi" not in at(r, theta=-theta0)["symbolic"]["theta"]


def own_roots(grad, lo, hi, n: int = 41, periodic=True) -> list[np.ndarray]:
    """This file's own search: scipy.optimize.root from a dense grid, wrapped, deduplicated."""
    found: list[np.ndarray] = []
    axis = np.linspace(lo, hi, n)
    for x0 in itertools.product(axis, axis):
        sol = scipy.optimize.root(grad, x0, tol=1e-13)
        if not sol.success or np.max(np.abs(grad(sol.x))) > 1e-9:
            continue
        x = np.angle(np.exp(1j * sol.x)) if periodic else sol.x
        x = np.where(x <= -math.pi + 1e-9, x + 2 * math.pi, x) if periodic else x
        if not any(np.allclose(x, y, atol=1e-6) for y in found):
            found.append(x)
    return found


def test_coupled_pendulums_each_equilibrium_once():
    """Two pendulums whose bobs are joined by a spring of rest length d (the pivots' distance):
    V = −mgl(cosθ₁ + cosθ₂) + ½k(|r₂ − r₁| − d)², searched here by finite differences of V."""
    m, length, k, d = 1.0, 1.0, 2.0, 1.0
    spec = {
        "coordinates": ["theta1", "theta2"],
        "parameters": {"m": m, "l": length, "g": G, "k": k, "d": d},
        "bodies": [
            {"name": "b1", "mass": "m", "position": ["l*sin(theta1)", "-l*cos(theta1)", 0]},
            {"name": "b2", "mass": "m", "position": ["d + l*sin(theta2)", "-l*cos(theta2)", 0]},
        ],
        "springs": [{"a": "b1", "b": "b2", "k": "k", "rest_length": "d"}],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }

    def V(q):
        r1 = np.array([length * math.sin(q[0]), -length * math.cos(q[0])])
        r2 = np.array([d + length * math.sin(q[1]), -length * math.cos(q[1])])
        return (
            -m * G * length * (math.cos(q[0]) + math.cos(q[1]))
            + k / 2 * (np.linalg.norm(r2 - r1) - d) ** 2
        )

    def grad(q, h=1e-6):
        return np.array([(V(q + h * e) - V(q - h * e)) / (2 * h) for e in np.eye(2)])

    expected = own_roots(grad, -math.pi, math.pi, n=13)
    got = [np.array([e["q"]["theta1"], e["q"]["theta2"]]) for e in solve(spec)["equilibria"]]
    assert len(got) == len(expected) == 4
    for x in expected:
        assert any(np.allclose(x, y, atol=1e-5) for y in got), (x, got)
    e = at(solve(spec), theta1=0.0, theta2=0.0)
    assert e["frequencies"] == pytest.approx(
        [math.sqrt(G / length), math.sqrt(G / length + 2 * k / m)]
    )


def test_pendulums_coupled_by_a_horizontal_spring_have_four_equilibria_not_duplicates():
    """V = −mgl(cosθ₁ + cosθ₂) + ½kl²(sinθ₁ − sinθ₂)², weak k: sinθ₁ = sinθ₂ = 0 only."""
    spec = {
        "coordinates": ["theta1", "theta2"],
        "parameters": {"m": 1.0, "l": 1.0, "g": G, "k": 0.5},
        "bodies": [
            {"name": "b1", "mass": "m", "position": ["l*sin(theta1)", "-l*cos(theta1)", 0]},
            {"name": "b2", "mass": "m", "position": ["2 + l*sin(theta2)", "-l*cos(theta2)", 0]},
        ],
        "potentials": [
            {"name": "coupling", "expression": "k*l**2*(sin(theta1) - sin(theta2))**2/2"}
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }
    r = solve(spec)
    got = sorted((round(e["q"]["theta1"], 9), round(e["q"]["theta2"], 9)) for e in r["equilibria"])
    pi = round(math.pi, 9)
    assert got == [(0.0, 0.0), (0.0, pi), (pi, 0.0), (pi, pi)]
    assert [e["kind"] for e in r["equilibria"]].count("stable") == 1


def test_spring_on_a_line_rests_on_both_sides_of_its_anchor():
    """V = ½k(|x| − ℓ₀)²: x = ±ℓ₀, each with ω = √(k/m); x = 0 is a corner, not an equilibrium."""
    m, k, L0 = 2.0, 8.0, 1.5
    spec = {
        "coordinates": ["x"],
        "parameters": {"m": m, "k": k, "L0": L0},
        "initial": {"x": 1.0},
        "points": [{"name": "anchor", "position": [0, 0, 0]}],
        "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
        "springs": [{"a": "anchor", "b": "b", "k": "k", "rest_length": "L0"}],
    }
    r = solve(spec)
    assert sorted(e["q"]["x"] for e in r["equilibria"]) == pytest.approx([-L0, L0])
    for e in r["equilibria"]:
        assert e["kind"] == "stable"
        assert e["frequencies"] == pytest.approx([math.sqrt(k / m)])


def test_double_pendulum_frequencies_match_the_linearized_closed_form():
    """M = [[(m1+m2)l1², m2 l1 l2], [m2 l1 l2, m2 l2²]], K = diag((m1+m2)g l1, m2 g l2):
    ω² = g[(m1+m2)(l1+l2) ± √((m1+m2)²(l1+l2)² − 4(m1+m2)m1 l1 l2)] / (2 m1 l1 l2)."""
    m1, m2, l1, l2 = 1.5, 0.5, 1.0, 0.7
    params = {"m1": m1, "m2": m2, "l1": l1, "l2": l2, "g": G}
    r = equilibria(derivation_of_scene("double_pendulum"), params)
    s, root = (
        (m1 + m2) * (l1 + l2),
        math.sqrt(((m1 + m2) * (l1 + l2)) ** 2 - 4 * (m1 + m2) * m1 * l1 * l2),
    )
    w2 = sorted(G * (s + sign * root) / (2 * m1 * l1 * l2) for sign in (1, -1))
    down = at(r, theta1=0.0, theta2=0.0)
    assert down["kind"] == "stable"
    assert down["frequencies"] == pytest.approx([math.sqrt(w) for w in w2], rel=1e-9)
    assert len(r["equilibria"]) == 4
    assert [e["kind"] for e in r["equilibria"]].count("unstable") == 3


def test_numeric_search_is_bounded_for_a_large_posted_spec():
    """Six coupled angles (a chain of pendulums with springs): the search ends in bounded time."""
    n = 6
    coords = [f"q{i}" for i in range(n)]
    spec = {
        "coordinates": coords,
        "parameters": {"m": 1.0, "l": 1.0, "g": G, "k": 3.0},
        "bodies": [
            {"name": f"b{i}", "mass": "m", "position": [f"{i} + l*sin(q{i})", f"-l*cos(q{i})", 0]}
            for i in range(n)
        ],
        "potentials": [
            {
                "name": "coupling",
                "expression": " + ".join(
                    f"k*(sin(q{i}) - sin(q{i + 1}))**2/2" for i in range(n - 1)
                ),
            }
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }
    d = derive_model(spec)
    start = time.perf_counter()
    r = equilibria(d, {})
    assert time.perf_counter() - start < 30
    e = at(r, **dict.fromkeys(coords, 0.0))
    assert e["kind"] == "stable"
    seen = [tuple(round(v, 6) for v in x["q"].values()) for x in r["equilibria"]]
    assert len(seen) == len(set(seen))
