"""Which conditions sympy's solver is asked to solve (issue 23, item 8; review round 4): a
condition in which a coordinate enters both inside and outside a trigonometric function
(k θ = m g l sin θ) has no closed form, and asking sympy cost an inverted pendulum on a torsion
spring 7-66 s of its answer. The roots come from the numeric search; here they are checked
against an independent root-finder on the hand-derived condition k θ = m g l sin θ, and the
stability against V'' = k − m g l cos θ.
"""

from __future__ import annotations

import math
import time

import pytest
import sympy as sp
from scipy.optimize import brentq

from mechanics.derive import derive_model
from mechanics.equilibria import _TRIG, equilibria
from mechanics.equilibrium_closed_form import mixes_trig

t = sp.Symbol("t")
th, x = sp.Function("theta")(t), sp.Function("x")(t)
k, m, g, ell = sp.symbols("k m g l", positive=True)


@pytest.mark.parametrize(
    ("expr", "mixed"),
    [
        (k * th - m * g * ell * sp.sin(th), True),
        (th * sp.sin(th), False),  # a product: θ = 0 or sin θ = 0
        (sp.sin(th) * (g - ell * sp.cos(th)), False),  # the spinning hoop
        (x * sp.sin(th) + k * x, False),  # x outside, θ inside: polynomial in x
        (th**2 * (k * th - sp.cos(th)), True),
    ],
)
def test_a_coordinate_inside_and_outside_a_trigonometric_function_is_recognised(expr, mixed):
    assert mixes_trig(expr, _TRIG) is mixed


def test_an_inverted_pendulum_on_a_torsion_spring_answers_quickly_and_right():
    p = {"m": 1.0, "l": 1.0, "g": 9.81, "k": 5.0}
    spec = {
        "title": "inverted pendulum on a torsion spring",
        "coordinates": ["theta"],
        "parameters": p,
        "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "l*cos(theta)", 0]}],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
        "potentials": [{"name": "torsion", "expression": "k*theta**2/2"}],
    }
    d = derive_model(spec)
    start = time.perf_counter()
    out = equilibria(d)
    elapsed = time.perf_counter() - start
    mgl = p["m"] * p["g"] * p["l"]
    leaning = brentq(lambda a: p["k"] * a - mgl * math.sin(a), 0.5, math.pi)
    expected = {0.0: "unstable", leaning: "stable", -leaning: "stable"}
    got = {e["q"]["theta"]: e["kind"] for e in out["equilibria"]}
    assert sorted(got) == pytest.approx(sorted(expected), abs=1e-9)
    for a, kind in expected.items():
        curvature = p["k"] - mgl * math.cos(a)
        assert kind == ("stable" if curvature > 0 else "unstable")
        assert got[min(got, key=lambda b: abs(b - a))] == kind
    assert elapsed < 15.0  # 7-66 s when sympy was asked; about 1 s on a quiet machine


def three_body(mu: float) -> dict:
    """The restricted three-body problem in the frame turning with the primaries (Ω = 1, unit
    separation, G(M₁ + M₂) = 1): masses 1 − μ at (−μ, 0) and μ at (1 − μ, 0)."""
    return {
        "title": "restricted three-body problem",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "mu": mu, "Omega": 1.0},
        "frames": [{"name": "H", "parent": "N", "axis": "z", "angle": "Omega*t"}],
        "bodies": [
            {"name": "p", "mass": "m", "position": {"frame": "H", "components": ["x", "y", 0]}}
        ],
        "potentials": [
            {
                "name": "gravity",
                "expression": "-m*(1-mu)/sqrt((x+mu)**2+y**2) - m*mu/sqrt((x-1+mu)**2+y**2)",
            }
        ],
    }


def collinear_points(mu: float) -> list[float]:
    """L1, L2, L3 on the x axis: x = (1 − μ)(x + μ)/|x + μ|³ + μ (x − 1 + μ)/|x − 1 + μ|³."""

    def f(x: float) -> float:
        a, b = x + mu, x - 1 + mu
        return x - (1 - mu) * a / abs(a) ** 3 - mu * b / abs(b) ** 3

    eps = 1e-9
    return sorted(
        brentq(f, lo, hi)
        for lo, hi in ((-2, -mu - eps), (-mu + eps, 1 - mu - eps), (1 - mu + eps, 2))
    )


@pytest.mark.parametrize(("mu", "triangle"), [(0.01, "gyroscopically stable"), (0.1, "unstable")])
def test_the_lagrange_points_come_quickly_with_rouths_criterion(mu, triangle):
    """L4, L5 at (½ − μ, ±√3/2), stable by Coriolis alone while 27 μ(1 − μ) < 1 (Routh: μ <
    0.0385); L1-L3 are saddles of the effective potential, unstable for every μ."""
    d = derive_model(three_body(mu))
    start = time.perf_counter()
    out = equilibria(d)
    elapsed = time.perf_counter() - start
    got = {(round(e["q"]["x"], 7), round(e["q"]["y"], 7)): e["kind"] for e in out["equilibria"]}
    expected = {(round(x, 7), 0.0): "unstable" for x in collinear_points(mu)}
    for sign in (1, -1):
        expected[(round(0.5 - mu, 7), round(sign * math.sqrt(3) / 2, 7))] = triangle
    assert got == expected
    assert elapsed < 15.0  # 10 s to minutes while sympy was asked; about 1 s on a quiet machine
