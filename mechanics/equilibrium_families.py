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


def _orientation(places: dict[str, np.ndarray]) -> tuple[float, ...]:
    """What a mirror image changes and a proper motion (determinant +1) keeps: in a plane
    z = const the signed area of every triple, in space the triple product of every quadruple.
    Distances alone merged the two cyclic orders of three beads on a ring, mirror images that
    no turn of the ring carries into one another: two circles of equilibria, not one (issue 25,
    item 1). A leading 0/1 keeps a planar key from being compared with a spatial one."""
    names = sorted(places)
    p = [places[n] for n in names]
    if len({round(float(x[2]), 12) for x in p}) <= 1:
        return (0.0,) + tuple(
            float(np.cross(p[j][:2] - p[i][:2], p[k][:2] - p[i][:2]))
            for i in range(len(p))
            for j in range(i + 1, len(p))
            for k in range(j + 1, len(p))
        )
    return (1.0,) + tuple(
        float(np.dot(p[j] - p[i], np.cross(p[k] - p[i], p[l] - p[i])))
        for i in range(len(p))
        for j in range(i + 1, len(p))
        for k in range(j + 1, len(p))
        for l in range(k + 1, len(p))  # noqa: E741
    )


def _key(places: dict[str, np.ndarray]) -> tuple[float, ...]:
    """Equal keys: the two configurations are congruent by a proper motion (same distances,
    same orientation), each of the other."""
    return _distances(places) + _orientation(places)


def _number(x: float, scale: float) -> str:
    """A length as read: round-off beside the scene's size (3.7e-16 of a distance 2) is 0."""
    return "0" if abs(x) <= 1e-9 * max(scale, 1.0) else f"{x:.4g}"


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
    """The family in words, saying only what the members found show: a circle or sphere about
    a fixed point (or a centre) where one particle moves alone at a fixed distance from it; the
    distances and orientation that stay where several bodies move (each member is a proper
    motion of the listed one); otherwise the points found. No symmetry of the scene is claimed
    that is not shown (a particle in the trough y = x² has none: issue 25, item 2)."""
    moving = _moving(m, members) if len(members) > 1 else []
    first = members[0]
    fixed = [n for n in sorted(first) if n not in moving]
    shape = "circle" if dim == 1 else "sphere"
    if len(moving) == 1 and dim in (1, 2):
        body = moving[0]
        for c in fixed:
            radius = [float(np.linalg.norm(p[body] - p[c])) for p in members]
            if max(radius) - min(radius) <= _SAME * max(1.0, max(radius)):
                return f"a {shape} of radius {radius[0]:.4g} about {c}, on which {body} rests"
        fit = _circle([p[body] for p in members]) if dim == 1 else None
        if fit is not None:
            centre, radius = fit
            at = ", ".join(_number(float(x), radius) for x in centre)
            return (
                f"a circle of radius {radius:.4g} about the point ({at}), on which {body} rests "
                "(the members found are turned into one another about that centre)"
            )
    if len(moving) > 1:
        names = sorted(first)
        scale = max(_distances(first), default=1.0)
        kept = [
            f"|{a} − {b}| = {_number(float(np.linalg.norm(first[a] - first[b])), scale)}"
            for i, a in enumerate(names)
            for b in names[:i]
            if a in moving or b in moving
        ]
        return (
            "the configurations with the same distances"
            + (f" ({', '.join(kept[:4])})" if kept else "")
            + " and the same orientation (no mirror image among them): each member found is "
            "the listed one turned, moved, or both"
        )
    places = [p[n] for p in members[:3] for n in moving[:1]]
    shown = ", ".join(f"({', '.join(f'{x:.3g}' for x in r + 0.0)})" for r in places)
    more = ", …" if len(members) > 3 else ""
    what = {1: "a curve", 2: "a surface"}.get(dim, "a set")
    who = f"{moving[0]} at " if moving else ""
    return (
        f"{what} through the points found ({who}{shown}{more}); no symmetry of the scene is "
        "shown to carry them into one another, so its shape is known from those points only"
    )


def _circle(points: list[np.ndarray]) -> tuple[np.ndarray, float] | None:
    """Centre and radius of the circle in a plane z = const through the points, when they lie
    on one (to ``_SAME``): the ring trough's members, about a centre no named point marks."""
    if len(points) < 4 or len({round(float(p[2]), 12) for p in points}) > 1:
        return None
    xy = np.array([p[:2] for p in points])
    A = np.column_stack([2 * xy, np.ones(len(xy))])
    b = np.sum(xy**2, axis=1)
    sol, *_ = np.linalg.lstsq(A, b, rcond=None)
    centre = sol[:2]
    radius = float(np.sqrt(max(sol[2] + centre @ centre, 0.0)))
    spread = np.linalg.norm(xy - centre, axis=1)
    if radius <= 0 or np.max(np.abs(spread - radius)) > _SAME * max(1.0, radius):
        return None
    return np.array([*centre, points[0][2]]), radius


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
        key = _key(places)
        for gkey, _, spots in self.groups:
            scale = max(1.0, *map(abs, gkey), *map(abs, key)) if key else 1.0
            if len(gkey) == len(key) and all(
                abs(a - b) <= _SAME * scale for a, b in zip(gkey, key, strict=True)
            ):
                spots.append(places)
                return True
        return False

    def add(self, q0: list[float], verdict: Any, result: dict) -> None:
        if verdict.family_dim and (places := self._places(q0)) is not None:
            self.groups.append((_key(places), result, [places]))

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
