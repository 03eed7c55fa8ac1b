"""A derivation is a function of the spec alone: not of the clock, not of what ran before.

The three systems below are larger than any built-in scene (a triple pendulum, a heavy symmetric
top through three Euler rotations, a six-link chain); their M and f are checked against sympy's
LagrangesMethod on a Lagrangian built here by hand from the positions, and the disk cache is
checked to serve only entries of this engine and of the expected shape.
"""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
from pathlib import Path

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

from benchmarks.derive import SYSTEMS
from mechanics.derive import derive_model

TRIPLE_PENDULUM = SYSTEMS["triple_pendulum"]
HEAVY_TOP = SYSTEMS["heavy_top"]
SIX_LINK_CHAIN = SYSTEMS["six_link_chain"]


# --- the clock cannot change a derivation ---------------------------------------------------

#: Derives a spec (argv[1], JSON) and prints its JSON without the one measured field, "seconds".
#: With argv[2] == "slow", every clock the process can read jumps ten minutes per reading, so any
#: wall-clock budget inside the derivation runs out at once.
CHILD = """
import json, sys, time
if sys.argv[2] == "slow":
    for name in ("perf_counter", "monotonic", "time", "process_time"):
        real = getattr(time, name)
        def jumping(real=real, calls=[0]):
            calls[0] += 1
            return real() + 600.0 * calls[0]
        setattr(time, name, jumping)
from mechanics.derive import derive
out = derive(json.loads(sys.argv[1]))
out.pop("seconds")
print(json.dumps(out, sort_keys=True))
"""


def test_triple_pendulum_is_the_same_in_fresh_processes_however_slow(tmp_path: Path) -> None:
    spec = json.dumps(TRIPLE_PENDULUM)
    runs = []
    for i, (pace, hash_seed) in enumerate((("slow", "1"), ("normal", "2"))):
        env = os.environ | {"LAGRANGE_LAB_CACHE": str(tmp_path / f"cache{i}")}
        env["PYTHONHASHSEED"] = hash_seed  # set iteration order must not leak into the output
        runs.append(
            subprocess.Popen(
                [sys.executable, "-c", CHILD, spec, pace],
                env=env,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
        )
    outputs = []
    for run in runs:
        stdout, stderr = run.communicate(timeout=600)
        assert run.returncode == 0, stderr
        outputs.append(stdout)
    slow, normal = outputs
    assert slow == normal
    derived = json.loads(normal)
    assert derived["equations"]["accelerations"] is not None  # small enough to solve, always
    assert not any("budget" in w for w in derived["warnings"])


def test_six_links_keep_m_qddot_equals_f_unsolved_and_say_why() -> None:
    d = derivations()["six_link_chain"]
    assert d.work.accelerations is None
    assert d.to_json()["equations"]["accelerations"] is None


# --- M and f against sympy's LagrangesMethod on a hand-built Lagrangian ----------------------


def chain_by_hand(n: int) -> tuple[LagrangesMethod, dict[str, sp.Symbol], list]:
    q = dynamicsymbols(f"theta1:{n + 1}")
    g = sp.Symbol("g")
    m = sp.symbols(f"m1:{n + 1}")
    ls = sp.symbols(f"l1:{n + 1}")
    N = ReferenceFrame("N")
    origin = Point("O")
    origin.set_vel(N, 0)
    previous, particles = origin, []
    for i in range(n):
        bob = previous.locatenew(f"bob{i}", ls[i] * (sp.sin(q[i]) * N.x - sp.cos(q[i]) * N.y))
        bob.set_vel(N, bob.pos_from(origin).dt(N))
        particle = Particle(f"bob{i}", bob, m[i])
        particle.potential_energy = m[i] * g * bob.pos_from(origin).dot(N.y)
        particles.append(particle)
        previous = bob
    L = Lagrangian(N, *particles)
    symbols = (
        {"g": g} | {f"m{i + 1}": m[i] for i in range(n)} | {f"l{i + 1}": ls[i] for i in range(n)}
    )
    return LagrangesMethod(L, q), symbols, q


def top_by_hand() -> tuple[LagrangesMethod, dict[str, sp.Symbol], list]:
    psi, theta, phi = q = dynamicsymbols("psi theta phi")
    m, A, C, length, g = sp.symbols("m A C l g")
    N = ReferenceFrame("N")
    P, Q, B = ReferenceFrame("P"), ReferenceFrame("Q"), ReferenceFrame("B")
    P.orient_axis(N, N.z, psi)
    Q.orient_axis(P, P.x, theta)
    B.orient_axis(Q, Q.z, phi)
    origin = Point("O")
    origin.set_vel(N, 0)
    G = origin.locatenew("G", length * B.z)
    G.set_vel(N, G.pos_from(origin).dt(N))
    top = RigidBody("top", G, B, m, (inertia(B, A, A, C), G))
    top.potential_energy = m * g * G.pos_from(origin).dot(N.z)
    symbols = {"m": m, "A": A, "C": C, "l": length, "g": g}
    return LagrangesMethod(Lagrangian(N, top), q), symbols, q


SYSTEMS = {
    "triple_pendulum": (TRIPLE_PENDULUM, lambda: chain_by_hand(3)),
    "heavy_top": (HEAVY_TOP, top_by_hand),
    "six_link_chain": (SIX_LINK_CHAIN, lambda: chain_by_hand(6)),
}

_derived: dict = {}


def derivations() -> dict:
    """Each system derived once for the whole module (the six-link chain costs seconds)."""
    if not _derived:
        _derived.update({name: derive_model(spec) for name, (spec, _) in SYSTEMS.items()})
    return _derived


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_mass_matrix_and_forcing_match_lagranges_method(name: str) -> None:
    d = derivations()[name]
    lm, theirs_symbols, their_q = SYSTEMS[name][1]()
    lm.form_lagranges_equations()
    rng = random.Random(11)
    for _ in range(5):
        state = {
            "params": {name: rng.uniform(0.5, 1.5) for name in theirs_symbols},
            "q": [rng.uniform(-3.0, 3.0) for _ in their_q],
            "q_dot": [rng.uniform(-2.0, 2.0) for _ in their_q],
        }
        ours = d.work.mass_matrix.tolist() + [list(d.work.forcing)]
        theirs = lm.mass_matrix.tolist() + [list(lm.forcing)]
        for our_row, their_row in zip(ours, theirs, strict=True):
            for a, b in zip(our_row, their_row, strict=True):
                x = value_at(a, state, d.model.params, d.model.q)
                y = value_at(b, state, theirs_symbols, their_q)
                assert x == pytest.approx(y, rel=1e-9, abs=1e-9), (name, a, b)


def value_at(expr: sp.Expr, state: dict, symbols: dict, q: list) -> float:
    """expr at a state given by parameter name and coordinate position (q, q̇), as a float."""
    t = dynamicsymbols._t
    values = {symbols[k]: v for k, v in state["params"].items()}
    values |= {qi.diff(t): r for qi, r in zip(q, state["q_dot"], strict=True)}
    values |= dict(zip(q, state["q"], strict=True))
    return float(msubs(expr, values))


def test_solved_accelerations_of_the_top_agree_with_m_inverse_f() -> None:
    d = derivations()["heavy_top"]
    assert d.work.accelerations is not None
    subs = {s: sp.Float(0.7 + 0.1 * i) for i, s in enumerate(d.model.params.values())}
    t = dynamicsymbols._t
    subs |= {qd: sp.Float(0.3 - 0.2 * i) for i, qd in enumerate(d.model.qd)}
    subs |= {q: sp.Float(0.9 + 0.3 * i) for i, q in enumerate(d.model.q)}
    assert t not in subs
    M = msubs(d.work.mass_matrix, subs)
    f = msubs(d.work.forcing, subs)
    expected = M.LUsolve(f)
    for ours, theirs in zip(d.work.accelerations, expected, strict=True):
        assert float(msubs(ours, subs)) == pytest.approx(float(theirs), rel=1e-9, abs=1e-12)
