"""A potential energy left out, named as such (the checker's rule; issue 23, item 7a).

`L = ½ m l² θ̇²` for a pendulum is T alone: the weight's −m g l cos θ is missing. It used to
read as "the small-angle approximation (cos θ ≈ 1)", because with cos θ = 1 that term is a
constant, and constants in L only move the datum. The cause is a forgotten V, and the
prediction view repeated the wrong cause to the student.

V is a sum of parts, one per conservative force (`mechanics.steps.energy.potential_parts`:
each body's weight m g h, each spring's ½ k (ℓ − ℓ₀)², each given potential). Each part leaves
its mark on every quantity: +V_i in V, −V_i in L, ∂V_i/∂q_j in q_j's equation of motion (times
the student's own scaling of it), −(M⁻¹ ∇V_i)_j in q̈_j. An answer that equals the derived
result with some parts taken away (proved, not sampled; up to a constant in V and L) is told
which parts are missing, by the force they come from. With the whole of V gone from L, the
rest may still be the small-angle form of T: that is said too, as a second line.
"""

from __future__ import annotations

import itertools
from typing import Any

import sympy as sp

from mechanics.check_approximations import small_angle
from mechanics.expr import to_latex
from mechanics.model import T as t
from mechanics.steps import partial
from mechanics.steps.energy import potential_parts, spring_words

#: A piece of V: the forces it comes from ((kind, name) of each), and the expression.
Piece = tuple[tuple[tuple[str, str], ...], sp.Expr]
#: Past this many parts of V, subsets are not tried one by one (2**k of them).
MAX_PARTS = 6
#: Past this many coordinates, q̈ is not re-solved without a part (M⁻¹ symbolically).
MAX_SOLVED_COORDINATES = 3


def missing_potential(judge: Any, given: sp.Expr, expected: sp.Expr) -> list[str]:
    """Lines naming the parts of V the answer leaves out, or [] when it is not that (or when
    that cannot be proved)."""
    from mechanics.check import constant_proof, zero_proof

    quantity, m = judge.quantity, judge.m
    if quantity == "T":
        return _potential_in_t(judge, given, expected)
    if quantity not in ("V", "L", "eom", "accel"):
        return []
    if quantity == "accel" and len(m.q) > MAX_SOLVED_COORDINATES:
        return []
    parts = _moving_parts(judge)
    if not parts or len(parts) > MAX_PARTS:
        return []
    motion_only = quantity in ("V", "L")  # there a constant difference is only the datum
    same = constant_proof if motion_only else zero_proof
    gap = judge.values(given - expected, motion_only)
    memo: dict[sp.Expr, tuple[sp.Expr, list[complex]]] = {}  # each piece's effect, once
    for pieces in _candidates(judge, parts):
        for _, piece in pieces:
            if piece not in memo:
                effect = _effect(judge, piece)
                memo[piece] = (effect, judge.values(effect, motion_only))
        effects = [memo[piece][0] for _, piece in pieces]
        marks = [memo[piece][1] for _, piece in pieces]
        if not _fits(gap, marks, motion_only):
            continue
        if same(given - (expected - sp.Add(*effects)), m) is True:
            return [_sentence(judge, pieces, len(pieces) == len(parts) and pieces == parts)]
    if quantity == "L":  # all of V gone, and T written in its small-angle form
        everything = sp.Add(*(_effect(judge, piece) for _, piece in parts))
        rest = small_angle(
            judge,
            given,
            expected - everything,
            subject="The rest of your L is the small-angle approximation of T",
        )
        if rest:
            return [_sentence(judge, parts, True), rest]
    return []


def _potential_in_t(judge: Any, given: sp.Expr, expected: sp.Expr) -> list[str]:
    """T written with V in it: T − V (which is L) or T + V (the energy), proved up to a
    constant (a datum that came along with V)."""
    from mechanics.check import _tidy, constant_proof, inline

    parts = _moving_parts(judge)
    if not parts:
        return []
    potential = sp.Add(*(p for _, p in parts))
    gap = judge.values(given - expected, True)
    for sign, what in ((-1, "T − V, which is L"), (1, "T + V, the energy")):
        if not _fits(gap, [judge.values(-sign * potential, True)], True):
            continue
        if constant_proof(given - expected - sign * potential, judge.m) is True:
            return [
                f"Your T is {what}: it has {'−V' if sign < 0 else '+V'} in it, with "
                f"V = {inline(_tidy(potential, judge.m))} the potential energy of "
                f"{_sources(parts)}. T is the kinetic energy alone (½ m v² "
                "of each body, ½ I ω² of each rigid body's rotation); the potential energy "
                "belongs in V."
            ]
    return []


def _candidates(judge: Any, parts: list[Piece]) -> Any:
    """What may have been left out, likeliest first: all of V; some of its parts (a weight, a
    spring); one or two of its terms (the m₂ g l₂ cos θ₂ of a double pendulum's V, whose
    cos θ₁ share the student kept), each named by the parts it comes from."""
    for k in range(len(parts), 0, -1):
        for chosen in itertools.combinations(parts, k):
            yield list(chosen)
    terms = _terms_of_V(judge, parts)
    if len(terms) > MAX_PARTS:
        return
    for k in (1, 2):
        for chosen in itertools.combinations(terms, k):
            yield list(chosen)


def _terms_of_V(judge: Any, parts: list[Piece]) -> list[Piece]:
    """V's terms (one per monomial of the motion) that are not whole parts already tried, each
    with the sources it comes from."""
    monomials = judge._canonical(sp.Add(*(piece for _, piece in parts)))
    wholes = [judge._canonical(piece) for _, piece in parts]
    out = []
    for mono, coeff in monomials.items():
        if mono == 1 or {mono: coeff} in wholes:
            continue
        sources = tuple(
            source
            for (named, _), whole in zip(parts, wholes, strict=True)
            if mono in whole
            for source in named
        )
        out.append((sources, coeff * mono))
    return out


def _moving_parts(judge: Any) -> list[Piece]:
    """V's parts that change with the motion (a fixed body's weight is a constant: no part of
    any equation), tidied as the derivation shows them, each with the force it comes from."""
    from mechanics.check import _tidy

    m = judge.m
    out = []
    for kind, name, part in potential_parts(m):
        part = _tidy(part, m)
        if part.has(*m.q, t):
            out.append((((kind, name),), part))
    return out


def _effect(judge: Any, part: sp.Expr) -> sp.Expr:
    """What the potential ``part`` puts into the quantity the judge compares against."""
    m, quantity = judge.m, judge.quantity
    if quantity == "V":
        return part
    if quantity == "L":
        return -part
    if quantity == "eom":  # q_j's equation holds +∂V/∂q_j, in the student's scaling
        return judge.scale * partial(part, m.q[judge.j], m)
    # q̈ = M⁻¹ (… − ∇V): the part's share of q̈_j, M read off the derived equations
    rows = [judge.d.work.eom_lhs[k] - judge.d.work.Q[k] for k in range(len(m.q))]
    inertia = sp.Matrix([[partial(r, a, m) for a in m.qdd] for r in rows])
    gradient = sp.Matrix([partial(part, q, m) for q in m.q])
    return -inertia.LUsolve(gradient)[judge.j]


def _fits(gap: list[complex], marks: list[list[complex]], constant: bool) -> bool:
    """Is gap + Σ marks zero (or one constant) at every sample, to the evaluation's precision
    relative to the sizes involved? A cheap screen before any proof."""
    rest = [g + sum(ms) for g, *ms in zip(gap, *marks, strict=True)]
    scale = max([abs(g) for g in gap] + [abs(x) for ms in marks for x in ms] + [1e-300])
    if any(x != x for x in rest):  # NaN: no number at a sample
        return False
    base = rest[0] if constant else 0
    return all(abs(x - base) <= 1e-9 * scale for x in rest)


def _sources(pieces: list[Piece]) -> str:
    """'the weight of the bob', 'the weights of the bob1 and the bob2', 'the spring k1 and the
    spring k2': the forces the pieces come from, each once."""
    named = list(dict.fromkeys(source for sources, _ in pieces for source in sources))
    weights = [name for kind, name in named if kind == "weight"]
    said = []
    if weights:
        noun = "weight" if len(weights) == 1 else "weights"
        said.append(f"the {noun} of " + _listed([f"the {w}" for w in weights]))
    said += [f"the {spring_words(name)}" for kind, name in named if kind == "spring"]
    said += [f"the potential {name}" for kind, name in named if kind == "potential"]
    return _listed(said)


def _listed(items: list[str]) -> str:
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} and {items[-1]}"


def _sentence(judge: Any, pieces: list[Piece], whole: bool) -> str:
    """The line for the pieces of V left out, in the quantity's own terms."""
    from mechanics.check import _tidy, inline

    m, quantity = judge.m, judge.quantity
    sources = _sources(pieces)
    energy = inline(_tidy(sp.Add(*(p for _, p in pieces)), m))
    if whole:
        missing = f"the potential energy of {sources}, {energy}, is missing"
    else:
        missing = f"part of the potential energy, {energy} (from {sources}), is missing"
    if quantity == "V":
        return (
            f"Your V is not all of it: {missing}. V sums the potential energy of every "
            "conservative force (m g h for each weight, ½ k (ℓ − ℓ₀)² for each spring)."
        )
    if quantity == "L":
        return (
            f"{'Your L is T alone' if whole else 'Your L is not T − V'}: {missing}. L = T − V, "
            "and leaving a potential out is no approximation: it takes that force out of the "
            "motion."
        )
    q = to_latex(m.q[judge.j])
    of = f"of its potential energy {energy}" if whole else f"of {energy} (from {sources})"
    if quantity == "eom":
        term = inline(_tidy(sp.Add(*(_effect(judge, p) for _, p in pieces)), m))
        force = f"the force of {sources}" if whole else "part of the force from the potential"
        return (
            f"Your equation leaves out {force}: the term {term}, "
            f"$\\partial V/\\partial {q}$ {of}, is missing."
        )
    force = f"the force of {sources}" if whole else f"part of the force of {sources}"
    return (
        f"Your {inline(m.qdd[judge.j])} is the acceleration without {force}: "
        f"$-\\partial V/\\partial q$ {of} is missing from it."
    )
