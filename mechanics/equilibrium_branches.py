"""Springs along a line: both sides of their anchors, and what an equilibrium on the far side
means.

A spring along a line is derived as ℓ = p without |·|, valid while p > 0 (the side of the
scene's own state). Its other side is a real configuration of the spring model: the spring
passed through its anchor, or two masses on a line passed through each other. Equilibria there
surprise a reader ("four stable equilibria" of two masses between walls, three of them with a
mass on the wrong side of another), so each is labelled with what it means, and every side is
searched, fewest reversed springs first (a three-mass chain between walls has four equilibria
with one spring reversed; searching sides in binary order stopped before the one with the first
spring reversed).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import sympy as sp

from mechanics.expr import to_plain

#: Sides searched in all, fewest reversed springs first (every side of up to four springs).
MAX_BRANCH_VARIANTS = 16


@dataclass
class Variant:
    """The equations with each spring along a line on one side of its anchor.

    Such a spring is derived as ℓ = p without |·|, valid while p > 0: an equilibrium on the other
    side (x = −ℓ₀) solves the equations with ℓ = −p. ½k(−p − ℓ₀)² − ½k(p − ℓ₀)² = 2kℓ₀p, so that
    variant's forcing is f − 2kℓ₀ ∂p/∂q, valid while −p > 0: no new derivation is needed."""

    model: Any
    mass_matrix: sp.Matrix
    forcing: sp.Matrix
    ranges: list[sp.Expr]
    label: str = ""
    #: The springs this side has reversed (on the other side of their anchor than the
    #: scene's own state), for the words that say what such an equilibrium means.
    reversed: list[Any] = field(default_factory=list)


def variants(m: Any, base: Variant, zeros: tuple) -> tuple[list[Variant], list[str]]:
    """Every side of every spring's anchor (bounded), fewest reversed springs first, with a
    note saying which were not searched.

    A spring whose rest length is 0 here has no sides: ½k p² is smooth through its anchor, where
    it rests when nothing else pulls (its range p > 0 had left that equilibrium out); nor has a
    spring of stiffness 0, which pulls on nothing."""
    to_zero = {p: sp.S.Zero for p in zeros}
    springs = [  # with k = 0 a spring exerts nothing: its side does not matter either
        s
        for s in m.springs
        if getattr(s, "branch", None) is not None
        and s.rest_length.xreplace(to_zero) != 0
        and s.k.xreplace(to_zero) != 0
    ]
    sides = sorted(itertools.product((False, True), repeat=len(springs)), key=sum)
    out, warnings = [], []
    for flips in sides:
        if len(out) >= MAX_BRANCH_VARIANTS:
            most = sum(flips) - 1
            warnings.append(
                f"{len(springs)} springs lie along lines: the sides of their anchors with at "
                f"most {most} spring{'s' if most != 1 else ''} reversed were searched for "
                f"equilibria ({len(out)} of {2 ** len(springs)} sides), not all of those with "
                f"more: equilibria may be missing there."
            )
            break
        forcing, ranges, where = base.forcing, [], []
        for s, flip in zip(springs, flips, strict=True):
            p = -s.branch if flip else s.branch
            if flip:
                extra = 2 * s.k * s.rest_length * sp.Matrix([s.branch.diff(q) for q in m.q])
                forcing = forcing - extra
            ranges.append(p)
            where.append(f"{s.name}: ℓ = {to_plain(p)}")
        flipped = [s for s, flip in zip(springs, flips, strict=True) if flip]
        out.append(Variant(m, base.mass_matrix, forcing, ranges, ", ".join(where), flipped))
    return out, warnings


def _moves(m: Any, place: str) -> bool:
    r = m.positions.get(place)
    return r is not None and any(c.has(*m.q) for c in r.to_matrix(m.N))


def _gap(m: Any, s: Any, state: dict) -> list[float] | None:
    """r_b − r_a of the spring in a state (q and parameters as sympy numbers), or None."""
    d = (m.positions[s.b] - m.positions[s.a]).to_matrix(m.N)
    to_x = {q: sp.Dummy() for q in m.q}  # q(t) first: t = 0 would make it q(0)
    at = {x: state[q] for q, x in to_x.items()}
    try:
        return [
            float(sp.S.Zero + c.xreplace(to_x).xreplace({**state, **at, m.names["t"]: 0}))
            for c in d
        ]
    except (TypeError, ValueError):
        return None


def _reference(m: Any, values: dict) -> dict:
    """The scene's own state: its initial values (0 where none) at these parameters."""
    state = {**values}
    for name, q in zip(m.coordinate_names, m.q, strict=True):
        state[q] = sp.Float(m.spec.initial.get(name, 0.0))
    return state


def meaning(m: Any, q0: list[float], values: dict) -> str:
    """What an equilibrium means where a spring along a line is inverted ('' where none is):
    its two ends lie the other way round than in the scene's own state (or, where that state
    has them at one spot, than the order a → b its spec names along the line's axis): two
    masses have passed each other, or a mass has passed through the spring's fixed anchor."""
    here = {**values, **{q: sp.Float(x) for q, x in zip(m.q, q0, strict=True)}}
    ref = _reference(m, values)
    parts = []
    for s in m.springs:
        if getattr(s, "branch", None) is None:
            continue
        now, then = _gap(m, s, here), _gap(m, s, ref)
        if now is None or then is None:
            continue
        if any(abs(x) > 1e-12 for x in then):
            inverted = sum(a * b for a, b in zip(now, then, strict=True)) < 0
            against = "than in the scene's own state"
        else:
            first = next((x for x in now if abs(x) > 1e-12), 0.0)
            inverted = first < 0
            against = f"than the order {s.a} → {s.b} the spec names"
        if not inverted:
            continue
        a, b = _moves(m, s.a), _moves(m, s.b)
        if a and b:
            what = f"{s.b} has passed {s.a}"
        elif a or b:
            body, anchor = (s.a, s.b) if a else (s.b, s.a)
            what = f"{body} has passed through {anchor}, the spring's anchor"
        else:
            continue
        parts.append(
            f"spring {s.name} inverted: {what} (its ends lie the other way round {against})"
        )
    if not parts:
        return ""
    return "; ".join(parts) + ", which the spring model allows and a real spring would not"
