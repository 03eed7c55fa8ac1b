"""Textbook closed forms, written out by hand, against the engine's solved accelerations."""

from __future__ import annotations

import pytest
import sympy as sp

from mechanics.derive import derivation_of_scene
from mechanics.model import T as t


def _syms(d):
    m = d.model
    s = dict(m.params)
    for name, q, qd in zip(m.coordinate_names, m.q, m.qd, strict=True):
        s[name], s[name + "_dot"] = q, qd
    return s


def _assert_same(a, b):
    assert sp.simplify(sp.expand_trig(a - b)) == 0, f"{a} != {b}"


def _acc(scene_id):
    d = derivation_of_scene(scene_id)
    return d, _syms(d), d.work.accelerations


CASES = {
    # θ̈ = −(g/l) sin θ
    "simple_pendulum": lambda s: [-s["g"] / s["l"] * sp.sin(s["theta"])],
    # ẍ = (m1 − m2) g / (m1 + m2)
    "atwood_machine": lambda s: [(s["m1"] - s["m2"]) * s["g"] / (s["m1"] + s["m2"])],
    # ẍ = (2/3) g sin α for a uniform disk rolling without slipping
    "rolling_disk": lambda s: [sp.Rational(2, 3) * s["g"] * sp.sin(s["alpha"])],
    # θ̈ = −(3g / 2l) sin θ: I_O = ml²/3 by the parallel-axis theorem
    "physical_pendulum": lambda s: [-3 * s["g"] / (2 * s["l"]) * sp.sin(s["theta"])],
    # m ẍ + c ẋ + k x = F0 cos ωt
    "spring_mass_damper": lambda s: [
        (s["F0"] * sp.cos(s["w"] * t) - s["c"] * s["x_dot"] - s["k"] * s["x"]) / s["m"]
    ],
    # s̈ = g sin α − μ g cos α sign(ṡ)
    "incline_friction": lambda s: [
        s["g"] * sp.sin(s["alpha"]) - s["mu"] * s["g"] * sp.cos(s["alpha"]) * sp.sign(s["s_dot"])
    ],
    # θ̈ = sin θ (Ω² cos θ − g/R)
    "bead_on_hoop": lambda s: [
        sp.sin(s["theta"]) * (s["Omega"] ** 2 * sp.cos(s["theta"]) - s["g"] / s["R"])
    ],
    # r̈ = r θ̇² − GM/r², θ̈ = −2 ṙ θ̇ / r
    "central_force": lambda s: [
        s["r"] * s["theta_dot"] ** 2 - s["G"] * s["M"] / s["r"] ** 2,
        -2 * s["r_dot"] * s["theta_dot"] / s["r"],
    ],
    # m ẍ1 = −k x1 − k12 (x1 − x2), m ẍ2 = −k x2 − k12 (x2 − x1)
    "coupled_oscillators": lambda s: [
        (-s["k"] * s["x1"] - s["k12"] * (s["x1"] - s["x2"])) / s["m"],
        (-s["k"] * s["x2"] - s["k12"] * (s["x2"] - s["x1"])) / s["m"],
    ],
    # elastic pendulum: r̈ = r θ̇² + g cos θ − (k/m)(r − l0), θ̈ = −(g sin θ + 2 ṙ θ̇)/r
    "elastic_pendulum": lambda s: [
        s["r"] * s["theta_dot"] ** 2
        + s["g"] * sp.cos(s["theta"])
        - s["k"] / s["m"] * (s["r"] - s["l0"]),
        -(s["g"] * sp.sin(s["theta"]) + 2 * s["r_dot"] * s["theta_dot"]) / s["r"],
    ],
}


@pytest.mark.parametrize("scene_id", sorted(CASES))
def test_accelerations_match_textbook(scene_id):
    _, s, acc = _acc(scene_id)
    for ours, expected in zip(acc, CASES[scene_id](s), strict=True):
        _assert_same(ours, expected)


def test_central_force_conserves_angular_momentum_and_energy():
    d = derivation_of_scene("central_force")
    s = _syms(d)
    names = {c["name"]: c for c in d.work.conserved}
    assert names["momentum"]["coordinate"] == "theta"
    _assert_same(names["momentum"]["expr"], s["m"] * s["r"] ** 2 * s["theta_dot"])
    expected_E = s["m"] * (s["r_dot"] ** 2 + s["r"] ** 2 * s["theta_dot"] ** 2) / 2 - (
        s["G"] * s["M"] * s["m"] / s["r"]
    )
    _assert_same(names["energy"]["expr"], expected_E)


def test_bead_on_hoop_has_jacobi_integral_not_energy():
    """The hoop is driven: T + V changes, h = ½mR²(θ̇² − Ω² sin²θ) − mgR cos θ does not."""
    d = derivation_of_scene("bead_on_hoop")
    s = _syms(d)
    (c,) = d.work.conserved
    assert c["name"] == "jacobi"
    m, R, W, g, th = s["m"], s["R"], s["Omega"], s["g"], s["theta"]
    h = m * R**2 * (s["theta_dot"] ** 2 - W**2 * sp.sin(th) ** 2) / 2 - m * g * R * sp.cos(th)
    _assert_same(c["expr"], h)


def test_damped_driven_oscillator_conserves_nothing():
    d = derivation_of_scene("spring_mass_damper")
    assert d.work.conserved == []
