"""Equilibria of the spring model that a reader would not expect: springs along a line passed
through their anchors, masses passed through each other (issue 23, item 4; review round 4 of
"no confident wrong word").

By hand: n equal masses on a line between walls at 0 and W, joined by n + 1 springs (k, rest
length L). Spring i has extension Δᵢ = xᵢ − xᵢ₋₁ with sign σᵢ, tension k(|Δᵢ| − L) sgn Δᵢ =
k(Δᵢ − σᵢ L), the same in every spring at rest: Δᵢ = T/k + σᵢ L with Σ Δᵢ = W, so T/k =
(W − L Σσ)/(n + 1), and the pattern exists where every sgn Δᵢ = σᵢ. Every one is a minimum
(V = Σ ½k(|Δᵢ| − L)² is a sum of convex pieces on each side). Three masses with W = 4, L = 1:
(1, 2, 3) and four with one spring inverted; one of them, spring 1 inverted (x₁ = −½), was
missed.
"""

from __future__ import annotations

import itertools

import pytest

from mechanics.derive import derive_model
from mechanics.equilibria import equilibria

NAMES = "ABC"


def chain(n: int, width: float, rest: float = 1.0, stops: bool = False) -> dict:
    bodies = [{"name": NAMES[i], "mass": "m", "position": [f"x{i + 1}", 0, 0]} for i in range(n)]
    ends = ["wl", *NAMES[:n], "wr"]
    spec = {
        "title": f"{n} masses between walls",
        "coordinates": [f"x{i + 1}" for i in range(n)],
        "parameters": {"m": 1.0, "k": 1.0, "L": rest, "W": width},
        "points": [
            {"name": "wl", "position": [0, 0, 0]},
            {"name": "wr", "position": ["W", 0, 0]},
        ],
        "bodies": bodies,
        "springs": [
            {"name": f"s{i + 1}", "a": a, "b": b, "k": "k", "rest_length": "L"}
            for i, (a, b) in enumerate(itertools.pairwise(ends))
        ],
    }
    if stops:  # the masses may not pass a wall or each other
        spec["stops"] = [
            {"name": f"order{i}", "when": w, "message": "out of order"}
            for i, w in enumerate(
                ["x1", *[f"x{i + 2} - x{i + 1}" for i in range(n - 1)], f"W - x{n}"]
            )
        ]
    return spec


def by_hand(n: int, width: float, rest: float = 1.0) -> dict[tuple, tuple[int, ...]]:
    """Every equilibrium (rounded positions) → the springs inverted there (1-based)."""
    out = {}
    for signs in itertools.product((1, -1), repeat=n + 1):
        tension = (width - rest * sum(signs)) / (n + 1)
        gaps = [tension + s * rest for s in signs]
        if all(g * s > 1e-12 for g, s in zip(gaps, signs, strict=True)):
            xs = list(itertools.accumulate(gaps))[:n]
            out[tuple(round(x, 9) for x in xs)] = tuple(i + 1 for i, s in enumerate(signs) if s < 0)
    return out


@pytest.mark.parametrize(("n", "width"), [(2, 3.0), (3, 4.0), (3, 5.0)])
def test_every_equilibrium_of_a_chain_between_walls_is_found_and_labelled(n, width):
    expected = by_hand(n, width)
    out = equilibria(derive_model(chain(n, width)))
    got = {tuple(round(e["q"][f"x{i + 1}"], 9) for i in range(n)): e for e in out["equilibria"]}
    assert set(got) == set(expected)
    ends = ["wl", *NAMES[:n], "wr"]
    for point, inverted in expected.items():
        e = got[point]
        assert e["kind"] == "stable"
        for i in range(1, n + 2):
            said = f"spring s{i} inverted" in e["reason"]
            assert said == (i in inverted), (point, i, e["reason"])
        for i in inverted:  # what it means: which end passed which
            a, b = ends[i - 1], ends[i]
            if a in NAMES and b in NAMES:
                assert f"{b} has passed {a}" in e["reason"]
            else:
                body, anchor = (b, a) if a == "wl" else (a, b)
                assert f"{body} has passed through {anchor}" in e["reason"]


def test_where_the_scenes_stops_forbid_the_inverted_ones_they_are_left_out_with_a_note():
    out = equilibria(derive_model(chain(2, 3.0, stops=True)))
    assert [tuple(round(v, 9) for v in e["q"].values()) for e in out["equilibria"]] == [(1.0, 2.0)]
    assert any("left out" in w and "3 equilibria" in w for w in out["warnings"])
