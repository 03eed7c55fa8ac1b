"""The systems a class posts together (issue 23, trust round 4, item 8): the restricted
three-body problem in a rotating frame, written two ways, and PyDy's two-link conical pendulum.
Their speed is the derive benchmark's (``python -m benchmarks derive three_body ...``);
here: their equations against sympy's LagrangesMethod built in this file from first principles
(frames, points, the potential written from the distances to the primaries) at random states,
the potential kept as written (its f had 3,313 operations when it was put over one denominator),
and the equations of motion of a 3-D chain too large to trace saying so.
"""

from __future__ import annotations

import random

import pytest
import sympy as sp
from sympy.physics.mechanics import (
    LagrangesMethod,
    Lagrangian,
    Particle,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
    msubs,
)

from benchmarks.systems import THREE_BODY, THREE_BODY_SI, conical_pendulum
from mechanics.derive import derive_model
from mechanics.provenance import TOO_LARGE, provenance

_derived: dict = {}


def derived(name: str):
    """Each system derived once for the module (the conical pendulum costs seconds)."""
    if name not in _derived:
        spec = {"three_body": THREE_BODY, "three_body_si": THREE_BODY_SI}.get(name)
        _derived[name] = derive_model(spec or conical_pendulum(2))
    return _derived[name]


def three_body_by_hand(si: bool) -> tuple[LagrangesMethod, dict, list]:
    """A particle at (x, y) in a frame turning at Ω about z, pulled by two fixed primaries."""
    x, y = q = dynamicsymbols("x y")
    t = dynamicsymbols._t
    m = sp.Symbol("m")
    if si:
        G, M1, M2, R = sp.symbols("G M1 M2 R")
        omega = sp.sqrt(G * (M1 + M2) / R**3)
        primaries = [(-M2 * R / (M1 + M2), G * M1), (M1 * R / (M1 + M2), G * M2)]
        symbols = {"m": m, "G": G, "M1": M1, "M2": M2, "R": R}
    else:
        mu, omega = sp.symbols("mu Omega")
        primaries = [(-mu, 1 - mu), (1 - mu, mu)]
        symbols = {"m": m, "mu": mu, "Omega": omega}
    N, H = ReferenceFrame("N"), ReferenceFrame("H")
    H.orient_axis(N, N.z, omega * t)
    origin = Point("O")
    origin.set_vel(N, 0)
    p = origin.locatenew("p", x * H.x + y * H.y)
    p.set_vel(N, p.pos_from(origin).dt(N))
    particle = Particle("p", p, m)
    particle.potential_energy = sum(-gm * m / sp.sqrt((x - at) ** 2 + y**2) for at, gm in primaries)
    return LagrangesMethod(Lagrangian(N, particle), q), symbols, q


def conical_by_hand() -> tuple[LagrangesMethod, dict, list]:
    """PyDy's two-link conical pendulum: link i turned from the one before by β_i about x, then
    α_i about the new z; each a rigid rod with a bob at its end, gravity along −y."""
    alpha = dynamicsymbols("alpha1:3")
    beta = dynamicsymbols("beta1:3")
    g = sp.Symbol("g")
    names = ("M", "m", "l", "Ixx", "Iyy", "Izz")
    per_link = {n: sp.symbols(f"{n}1:3") for n in names}
    N = ReferenceFrame("N")
    origin = Point("O")
    origin.set_vel(N, 0)
    parent, start, bodies = N, origin, []
    for i in range(2):
        turned = ReferenceFrame(f"T{i}")
        turned.orient_axis(parent, parent.x, beta[i])
        link_frame = ReferenceFrame(f"L{i}")
        link_frame.orient_axis(turned, turned.z, alpha[i])
        length = per_link["l"][i]
        centre = start.locatenew(f"G{i}", -length / 2 * link_frame.y)
        bob_point = start.locatenew(f"P{i}", -length * link_frame.y)
        for point in (centre, bob_point):
            point.set_vel(N, point.pos_from(origin).dt(N))
        rod_inertia = inertia(
            link_frame, per_link["Ixx"][i], per_link["Iyy"][i], per_link["Izz"][i]
        )
        rod = RigidBody(f"link{i}", centre, link_frame, per_link["M"][i], (rod_inertia, centre))
        rod.potential_energy = per_link["M"][i] * g * centre.pos_from(origin).dot(N.y)
        bob = Particle(f"bob{i}", bob_point, per_link["m"][i])
        bob.potential_energy = per_link["m"][i] * g * bob_point.pos_from(origin).dot(N.y)
        bodies += [rod, bob]
        parent, start = link_frame, bob_point
    symbols = {"g": g} | {f"{n}{i + 1}": per_link[n][i] for n in names for i in range(2)}
    return LagrangesMethod(Lagrangian(N, *bodies), [*alpha, *beta]), symbols, [*alpha, *beta]


BY_HAND = {
    "three_body": lambda: three_body_by_hand(si=False),
    "three_body_si": lambda: three_body_by_hand(si=True),
    "conical_pendulum_2": conical_by_hand,
}


def value_at(expr: sp.Expr, state: dict, symbols: dict, q: list) -> float:
    """expr at a state given by parameter name, time and coordinate position, as a float."""
    t = dynamicsymbols._t
    values = {symbols[k]: v for k, v in state["params"].items()}
    values |= {qi.diff(t, 2): r for qi, r in zip(q, state["q_ddot"], strict=True)}
    values |= {qi.diff(t): r for qi, r in zip(q, state["q_dot"], strict=True)}
    values |= dict(zip(q, state["q"], strict=True))
    return float(sp.sympify(msubs(expr, values)).subs(t, state["t"]))


@pytest.mark.parametrize("name", list(BY_HAND))
def test_equations_of_motion_match_lagranges_method_from_first_principles(name: str) -> None:
    d = derived(name)
    lm, symbols, their_q = BY_HAND[name]()
    lm.form_lagranges_equations()
    rng = random.Random(23)
    n = len(their_q)
    for _ in range(4):
        state = {
            "params": {
                k: rng.uniform(0.05, 0.45) if k == "mu" else rng.uniform(0.5, 1.5) for k in symbols
            },
            "q": [rng.uniform(-2.0, 2.0) for _ in range(n)],
            "q_dot": [rng.uniform(-1.5, 1.5) for _ in range(n)],
            "q_ddot": [rng.uniform(-1.0, 1.0) for _ in range(n)],
            "t": rng.uniform(0.0, 3.0),
        }
        ours = d.work.mass_matrix.tolist() + [list(d.work.forcing)]
        theirs = lm.mass_matrix.tolist() + [list(lm.forcing)]
        for our_row, their_row in zip(ours, theirs, strict=True):
            for a, b in zip(our_row, their_row, strict=True):
                x = value_at(a, state, d.model.params, d.model.q)
                y = value_at(b, state, symbols, their_q)
                assert x == pytest.approx(y, rel=1e-9, abs=1e-9), (name, a, b)
        if d.work.accelerations is not None:  # q̈ solved: M q̈ = f at the solved q̈
            M = [[value_at(e, state, d.model.params, d.model.q) for e in row] for row in ours[:n]]
            f = ours[n]
            acc = [value_at(a, state, d.model.params, d.model.q) for a in d.work.accelerations]
            for j in range(n):
                lhs = sum(M[j][k] * acc[k] for k in range(n))
                assert lhs == pytest.approx(value_at(f[j], state, d.model.params, d.model.q))


@pytest.mark.parametrize("name", ["three_body", "three_body_si"])
def test_the_potential_keeps_one_term_per_primary_as_written(name: str) -> None:
    """V = −G M₁ m/r₁ − G M₂ m/r₂ prints as two terms, each over the root of its own distance
    squared, unexpanded; f stays that small (3,313 and 278,391 operations over one denominator)."""
    d = derived(name)
    V = d.work.V
    roots = [p for p in V.atoms(sp.Pow) if p.exp == sp.Rational(-1, 2)]
    assert len(roots) == 2, V
    for r in roots:  # (x − a)² + y²: two terms, the square not multiplied out
        assert len(r.base.args) == 2, r
    for e in d.work.forcing:
        assert sp.count_ops(e) < 150, e


def test_a_3d_chain_too_large_to_trace_says_so_and_still_traces_its_energies() -> None:
    """Tracing each EoM term of the two-link conical pendulum to its origins took longer than
    the derivation; past the size-weighted budget it says so, and T, V and Q_j stay traced."""
    out = provenance(derived("conical_pendulum_2"))
    assert out["T"]["traced"] and out["V"]["traced"]
    for eq in out["eom"].values():
        assert eq["lhs"] == {"traced": False, "reason": TOO_LARGE, "terms": [], "cancelled": []}
