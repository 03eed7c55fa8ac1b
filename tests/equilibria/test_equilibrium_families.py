"""A continuum of equilibria is reported once, with its dimension and shape (issue 23, item 2;
review round 4 of "no confident wrong word").

By hand: a particle in a plane on a spring of rest length ℓ₀ anchored at o rests wherever
|r − o| = ℓ₀, a circle (in space, a sphere), and oscillates across it with ω² = k/m; along it no
force acts. Two masses joined by a spring and free in a plane rest wherever |r₂ − r₁| = ℓ₀: a
3-dimensional family (two translations, one turn). A symmetric double well V = c(x² − 1)² has two
isolated minima at x = ±1 (congruent, not a family) and a maximum at 0: they stay three entries.
"""

from __future__ import annotations

import math

import pytest

from mechanics.derive import derive_model
from mechanics.equilibria import equilibria


def anchored(rest: float, dims: int) -> dict:
    coords = ["x", "y", "z"][:dims]
    return {
        "title": "particle on an anchored spring",
        "coordinates": coords,
        "parameters": {"m": 1.0, "k": 4.0, "L": rest},
        "points": [{"name": "o", "position": [0, 0, 0]}],
        "bodies": [{"name": "p", "mass": "m", "position": [*coords, *[0] * (3 - dims)]}],
        "springs": [{"name": "s", "a": "o", "b": "p", "k": "k", "rest_length": "L"}],
    }


@pytest.mark.parametrize("rest", [1.0, 1.5])
def test_a_circle_of_equilibria_reads_as_a_circle(rest):
    out = equilibria(derive_model(anchored(rest, 2)))
    [e] = out["equilibria"]
    assert math.hypot(e["q"]["x"], e["q"]["y"]) == pytest.approx(rest, rel=1e-9)
    assert e["kind"] == "stable" and e["frequencies"] == pytest.approx([2.0], rel=1e-9)
    assert any(f"circle of radius {rest:.4g} about o" in w for w in out["warnings"])
    assert any("dimension 1" in w for w in out["warnings"])
    assert not any("More than" in w for w in out["warnings"])


def test_a_sphere_of_equilibria_reads_as_a_sphere():
    out = equilibria(derive_model(anchored(1.0, 3)))
    [e] = out["equilibria"]
    assert math.dist([0, 0, 0], list(e["q"].values())) == pytest.approx(1.0, rel=1e-9)
    assert any("sphere of radius 1 about o" in w and "dimension 2" in w for w in out["warnings"])


def test_congruent_isolated_equilibria_are_not_merged_into_a_family():
    spec = {
        "title": "double well",
        "coordinates": ["x"],
        "parameters": {"m": 1.0, "c": 1.0},
        "points": [{"name": "o", "position": [0, 0, 0]}],
        "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
        "potentials": [{"name": "well", "expression": "c*(x**2 - 1)**2"}],
    }
    out = equilibria(derive_model(spec))
    got = sorted((round(e["q"]["x"], 9), e["kind"]) for e in out["equilibria"])
    assert got == [(-1.0, "stable"), (0.0, "unstable"), (1.0, "stable")]
    assert not any("continuum" in w.lower() for w in out["warnings"])
