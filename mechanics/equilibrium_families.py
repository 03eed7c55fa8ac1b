"""Continua of equilibria, reported once: with their dimension, their shape where it has a
name (a circle, a sphere), and one verdict.

Two masses joined by a spring and free in a plane rest wherever the spring has its rest length:
a 3-dimensional family (two translations and a turn of the whole); a particle on a spring of
rest length ℓ₀ anchored at a point rests anywhere on the circle of radius ℓ₀ about it. A search
for points samples such a set at random, and the list read "more than 24 equilibria" scattered
over it. Here the members are grouped by what the scene's symmetries keep (the distances
between every body and every named point) once the higher-order test has shown that the point
lies on a family (``Verdict.family_dim`` > 0): each group is listed once.

Only for scenes of particles, whose positions are their whole configuration (a rigid body's
orientation is not in its position).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import sympy as sp

#: Members whose distances agree to this (relative) belong to one family.
_SAME = 1e-6


def _distances(places: dict[str, np.ndarray]) -> tuple[float, ...]:
    names = sorted(places)
    return tuple(
        float(np.linalg.norm(places[a] - places[b])) for i, a in enumerate(names) for b in names[:i]
    )


def _moving(m: Any, members: list[dict[str, np.ndarray]]) -> list[str]:
    """The places that are not at one spot over the members (the bodies the family moves)."""
    first = members[0]
    return [
        n
        for n in sorted(first)
        if any(
            np.linalg.norm(p[n] - first[n]) > 1e-9 * max(1.0, float(np.linalg.norm(first[n])))
            for p in members[1:]
        )
    ]


def describe(m: Any, dim: int, members: list[dict[str, np.ndarray]]) -> str:
    """The family in words: a circle or sphere about a fixed point where one particle moves
    alone at a fixed distance from it, otherwise what stays fixed along it."""
    moving = _moving(m, members) if len(members) > 1 else []
    first = members[0]
    fixed = [n for n in sorted(first) if n not in moving]
    if len(moving) == 1 and fixed and dim in (1, 2):
        body = moving[0]
        for c in fixed:
            radius = [float(np.linalg.norm(p[body] - p[c])) for p in members]
            if max(radius) - min(radius) <= _SAME * max(1.0, max(radius)):
                shape = "circle" if dim == 1 else "sphere"
                return f"a {shape} of radius {radius[0]:.4g} about {c}, on which {body} rests"
    names = sorted(first)
    kept = [
        f"|{a} − {b}| = {np.linalg.norm(first[a] - first[b]):.4g}"
        for i, a in enumerate(names)
        for b in names[:i]
        if a in moving or b in moving
    ]
    return (
        "the configurations with the same distances"
        + (f" ({', '.join(kept[:4])})" if kept else "")
        + ", which the scene's symmetry (moving or turning the whole) carries into one another"
    )


class Continua:
    """The families met so far: a root whose distances match one that the higher-order test
    found on a family (``family_dim`` > 0) is one of its members, counted and not judged again
    (its verdict is the family's). Isolated points are never grouped, even where congruent (a
    symmetric double well's two minima are two equilibria)."""

    def __init__(self, m: Any, values: dict) -> None:
        self.m, self.values = m, values
        self.on = all(b.kind == "particle" for b in m.bodies)
        anchored = {"O"} & {x for s in m.springs for x in (s.a, s.b)}
        self.names = [n for n in m.positions if n != "O" or anchored]
        xs = [sp.Dummy(f"q{j}") for j in range(len(m.q))]
        to_x = dict(zip(m.q, xs, strict=True))  # q(t) first: t = 0 would make it q(0)
        rows = [
            list(m.positions[n].to_matrix(m.N).xreplace(to_x).xreplace(values)) for n in self.names
        ]
        rows = [[sp.S.Zero + e.xreplace({m.names["t"]: sp.S.Zero}) for e in r] for r in rows]
        self.where = sp.lambdify(xs, rows, "numpy") if self.on else None
        #: (distances, listed result, its places, every member's places)
        self.groups: list[tuple[tuple, dict, list[dict[str, np.ndarray]]]] = []

    def _places(self, q0: list[float]) -> dict[str, np.ndarray] | None:
        if self.where is None:
            return None
        try:
            with np.errstate(all="ignore"):
                rows = [np.array(r, dtype=float).reshape(3) for r in self.where(*q0)]
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return None
        if not all(np.all(np.isfinite(r)) for r in rows):
            return None
        return dict(zip(self.names, rows, strict=True))

    def member(self, q0: list[float]) -> bool:
        if not self.groups:
            return False
        places = self._places(q0)
        if places is None:
            return False
        key = _distances(places)
        for gkey, _, spots in self.groups:
            scale = max(1.0, *map(abs, gkey), *map(abs, key)) if key else 1.0
            if all(abs(a - b) <= _SAME * scale for a, b in zip(gkey, key, strict=True)):
                spots.append(places)
                return True
        return False

    def add(self, q0: list[float], verdict: Any, result: dict) -> None:
        if verdict.family_dim and (places := self._places(q0)) is not None:
            self.groups.append((_distances(places), result, [places]))

    def describe(self, results: list[dict], verdicts: list) -> None:
        """The family sentence on each listed member's verdict (said once, in the warnings)."""
        for _, result, spots in self.groups:
            if result not in results or len(spots) < 2:
                continue
            v = verdicts[results.index(result)]
            v.family = (
                f"A continuum of equilibria of dimension {v.family_dim}: "
                f"{describe(self.m, v.family_dim, spots)}. The search met it {len(spots)} "
                "times; it is listed once, at "
                + ", ".join(f"{k} = {x:.4g}" for k, x in result["q"].items())
                + f", and every point of it has the same verdict ({v.kind})."
            )


def crowded(points: list[dict[int, float]], periods: dict[int, float]) -> bool:
    """Do some of the equilibria found lie next to each other (1e-3 apart), as points of a
    continuum the search samples do? A 6-link chain's 2⁶ = 64 isolated ones do not: a
    'continuum?' there was a false hint."""
    points = points[:100]
    for i, a in enumerate(points):
        for b in points[:i]:
            gap = 0.0
            for j in set(a) | set(b):
                diff = a.get(j, 0.0) - b.get(j, 0.0)
                if j in periods:
                    diff = math.remainder(diff, periods[j])
                gap = max(gap, abs(diff) / max(1.0, abs(a.get(j, 0.0))))
            if gap < 1e-3:
                return True
    return False
