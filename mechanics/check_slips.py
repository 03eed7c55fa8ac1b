"""A sign slipped inside a factor the student grouped, named in the student's own terms.

−(m₁ + m₂) g l₁ sin θ₁ typed as −(m₁ − m₂) g l₁ sin θ₁ used to come back as "the term
g l₁ (m₁ + m₂) sin θ₁ has the coefficient g l₁ (m₁ − m₂) instead of …": the derived result's
term, restated, where the student wrote one sign inside one bracket (issue 23, item 7c). Here
every bracket the student typed that holds a sum of several parameters (no coordinate, rate or
time) is tried with the sign of one (then two) of its terms flipped, in the text as typed, at
that bracket only; when the answer so changed is right (proved: equal, equal up to a constant
for V and L, a constant multiple for an equation of motion), the slip is named by the bracket
the student typed and the term it sits in. Nothing is claimed on samples alone.
"""

from __future__ import annotations

import cmath
import itertools
from typing import Any

import sympy as sp

from mechanics.answers import read_answer
from mechanics.expr import ExprError
from mechanics.model import T as t
from mechanics.steps import partial

#: A bracket with more terms than this is not tried (2**k sign patterns).
MAX_GROUP_TERMS = 4
_ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth")
#: A bracket's text longer than this is not read as a sum of parameters.
MAX_GROUP_TEXT = 60
#: At most this many changed answers are judged per check (each is a parse and a proof).
MAX_TRIES = 24


def sign_in_group(judge: Any, expected: sp.Expr, fb: list[str]) -> bool:
    """Append the line and return True when one sign flipped inside one typed bracket of
    parameters makes the answer right; False (fb untouched) otherwise."""
    text = getattr(judge, "text", "")
    if not text or "(" not in text:
        return False
    tries = 0
    for start, end in _brackets(text):
        factor = _parameter_sum(judge, text[start:end])
        if factor is None:
            continue
        for flipped in _flips(factor):
            tries += 1
            if tries > MAX_TRIES:
                return False
            changed = f"{text[:start]}{_plain(judge, flipped)}{text[end:]}"
            try:
                candidate, _ = read_answer(
                    judge.d, judge.quantity, changed, judge.j, exact_decimals=True
                )
            except ExprError:
                continue
            if _right(judge, candidate, expected):
                same = [b for b in _brackets(text) if text[b[0] : b[1]] == text[start:end]]
                n = same.index((start, end))
                which = "" if len(same) == 1 else _ORDINALS[n] if n < 8 else f"number {n + 1}"
                fb.append(_sentence(judge, factor, flipped, which, candidate))
                return True
    return False


def sign_of_a_term(judge: Any, expected: sp.Expr) -> list[str]:
    """One term of the answer, as the student wrote it, whose sign flipped makes the answer
    right (m₁ g l₁ sin θ₁ − m₂ g l₁ sin θ₁ for (m₁ + m₂) g l₁ sin θ₁): named by that term, not
    by the derived term it merges into. [] when no single term does (proved, as for brackets)."""
    terms = sp.Add.make_args(judge.given)
    if not 1 < len(terms) <= MAX_TRIES:
        return []
    motion = judge.quantity in ("eom", "V", "L")
    given = judge.values(judge.given, motion)  # each candidate's values: given − 2 · term
    for term in terms:
        flipped = [g - 2 * x for g, x in zip(given, judge.values(term, motion), strict=True)]
        if _right(judge, judge.given - 2 * term, expected, flipped):
            moved = judge._moved_term(term)
            return [
                f"Sign error in your term {judge._show(term)}{moved}: it should be "
                f"{judge._show(-term)}. With that one sign changed, the rest of your answer "
                "is right."
            ]
    return []


def _brackets(text: str) -> list[tuple[int, int]]:
    """(start, end) of the inside of every balanced (…) in ``text``, innermost first."""
    spans, stack = [], []
    for i, ch in enumerate(text):
        if ch == "(":
            stack.append(i + 1)
        elif ch == ")" and stack:
            spans.append((stack.pop(), i))
    return spans


def _parameter_sum(judge: Any, inner: str) -> sp.Expr | None:
    """The bracket's content when it is a sum of 2 to MAX_GROUP_TERMS terms, at least two of
    them holding a parameter, and no coordinate, rate or time; else None. A bracket longer
    than MAX_GROUP_TEXT characters is no such sum (and a hostile answer's hundreds of nested
    brackets are not each parsed)."""
    if "=" in inner or not inner.strip() or len(inner) > MAX_GROUP_TEXT:
        return None
    try:
        factor, _ = read_answer(judge.d, judge.quantity, inner, judge.j, exact_decimals=True)
    except ExprError:
        return None
    m = judge.m
    if not isinstance(factor, sp.Add) or factor.has(*m.q, *m.qd, *m.qdd, t):
        return None
    terms = factor.args
    if not 2 <= len(terms) <= MAX_GROUP_TERMS or sum(bool(a.free_symbols) for a in terms) < 2:
        return None
    return factor


def _flips(factor: sp.Expr) -> list[sp.Expr]:
    """The factor with the sign of one term flipped, then of two (never all: that is the whole
    factor's sign, a sign error of the term, which the term-by-term comparison names)."""
    terms = factor.args
    out = []
    for k in range(1, len(terms)):
        for chosen in itertools.combinations(range(len(terms)), k):
            out.append(sp.Add(*(-a if i in chosen else a for i, a in enumerate(terms))))
    return out


def _plain(judge: Any, expr: sp.Expr) -> str:
    """A parameter expression as answer text, with the scene's own parameter names."""
    names = {sym: sp.Symbol(name) for name, sym in judge.m.params.items()}
    return sp.sstr(expr.xreplace(names))


def _right(
    judge: Any, candidate: sp.Expr, expected: sp.Expr, values: list[complex] | None = None
) -> bool:
    """Would the changed answer be right, as the quantity asks? Screened at the samples (its
    ``values`` there when the caller has them: the motion's states for an equation, V and L),
    then proved."""
    from mechanics.check import _never_zero, constant_proof, zero_proof

    quantity, m = judge.quantity, judge.m
    motion = quantity in ("eom", "V", "L")
    mine = values if values is not None else judge.values(candidate, motion)
    theirs = _expected_values(judge, expected, motion)
    if quantity == "eom":
        ratios = [x / y for x, y in zip(mine, theirs, strict=True) if abs(y) > 1e-12]
        if len(ratios) < len(mine) // 2 or not _one_number(ratios, None) or ratios[0] == 0:
            return False
        if judge._multiple_proof(candidate, expected) is not True:
            return False
        qdd = m.qdd[judge.j]  # a multiple that vanishes at some parameters hides the equation
        return _never_zero(partial(candidate, qdd, m) / partial(expected, qdd, m))
    gaps = [x - y for x, y in zip(mine, theirs, strict=True)]
    if quantity in ("V", "L"):
        return _one_number(gaps, None) and constant_proof(candidate - expected, m) is True
    return _one_number(gaps, 0) and zero_proof(candidate - expected, m) is True


def _expected_values(judge: Any, expected: sp.Expr, motion: bool) -> list[complex]:
    """The expected result at the samples, once per check."""
    memo = judge.__dict__.setdefault("_slip_memo", {})
    key = (expected, motion)
    if key not in memo:
        memo[key] = judge.values(expected, motion)
    return memo[key]


def _one_number(xs: list[complex], value: complex | None) -> bool:
    """Are all of ``xs`` finite and one number (``value`` when given, else the first), to the
    checker's tolerance?"""
    from mechanics.check import TOLERANCE

    if not xs or not all(cmath.isfinite(x) for x in xs):
        return False
    target = xs[0] if value is None else value
    return all(abs(x - target) <= TOLERANCE * max(1.0, abs(target), abs(x)) for x in xs)


def _sentence(judge: Any, factor: sp.Expr, flipped: sp.Expr, which: str, candidate: sp.Expr) -> str:
    """'Sign error inside your factor (m₁ − m₂), in your term …: it should be (m₁ + m₂).'"""
    from mechanics.check import _as_written, inline

    fixed = set(sp.Add.make_args(candidate))  # the student's term is the one the fix changes
    mine = [
        x
        for x in sp.Add.make_args(judge.given)
        if (x.has(factor) or x.has(-factor)) and x not in fixed
    ]
    where = ""
    if len(mine) == 1:
        inertia = judge.quantity == "eom" and mine[0].has(judge.m.qdd[judge.j])
        what = "inertia term (the one with the acceleration)" if inertia else "term"
        where = f", in your {what} {_as_written(_as_typed(mine[0], factor))}"
    if which:
        where = f" (the {which} of your brackets that read so){where}"
    return (
        f"Sign error inside your factor {inline(factor)}{where}: it should be "
        f"{inline(flipped)}. With that one sign changed, the rest of your answer is right."
    )


def _as_typed(term: sp.Expr, factor: sp.Expr) -> sp.Expr:
    """The term with the student's bracket shown as typed: sympy takes the minus sign of
    −(m₁ + m₂) g x into the bracket, g x (−m₁ − m₂), a bracket nobody wrote."""
    if term.has(factor) or not term.has(-factor):
        return term
    return -term.xreplace({-factor: sp.S.One}) * sp.UnevaluatedExpr(factor)
