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
