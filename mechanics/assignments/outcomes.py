"""Stable, parameter-free outcome codes: what kind of answer a student gave, countable across a
class ("40 % dropped a term of T": ``T.missing_term``).

A code is ``<quantity>.<kind>``: the quantity prefix is one of T, V, L, Q, eom, accel, p (a
momentum); the kind comes from the checker's verdict (mechanics/check.py) through the one table
`KINDS` below, tried in order: the first row that matches one of the verdict's feedback lines
names the outcome. The feedback's wording may change; a code may not (its meaning is the row's
description): docs/assignments.md prints this table, and tests/assignments/test_outcome_codes.py
holds one hand-written wrong answer per code.

Two kinds come from outside the checker: ``unreadable`` (the answer does not parse: no attempt is
used) and ``cannot_decide`` (the checker ran past its budget, or could not prove or refute the
answer: no attempt is used either).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

#: The code's prefix for each checker quantity.
PREFIX = {"T": "T", "V": "V", "L": "L", "Q": "Q", "eom": "eom", "accel": "accel", "momentum": "p"}
PREFIX |= {"equilibrium": "q0", "frequency": "omega"}


@dataclass(frozen=True)
class Kind:
    name: str
    pattern: str  # a regular expression searched for at the start of a feedback line
    meaning: str
    credit: bool = False  # an outcome that scores the part in full


#: Ordered: the first kind whose pattern starts a feedback line is the outcome.
KINDS: tuple[Kind, ...] = (
    Kind("correct", r"Correct(\.|:)", "right (an equation also up to a non-zero factor)", True),
    Kind(
        "correct_up_to_constant",
        r"Correct up to a constant",
        "right up to an additive constant (V or L: another datum)",
        True,
    ),
    Kind("cannot_decide", r"Not confirmed", "the checker could neither prove nor refute it"),
    Kind(
        "undefined",
        r"Your answer (has no value|divides by)",
        "divides by zero, or has no value at the scene's states",
    ),
    Kind(
        "no_acceleration",
        r"(Your equation reduces to 0 = 0|The accelerations in your equation cancel|"
        r"An equation of motion must contain)",
        "an equation of motion without its acceleration (or an identity)",
    ),
    Kind(
        "other_coordinate",
        r"This is the equation of motion for",
        "the equation of another coordinate",
    ),
    Kind(
        "vanishing_factor",
        r"(Your equation holds along the motion, but it is the derived equation for .* "
        r"multiplied by|Your equation is the derived one)",
        "the equation multiplied by a factor that can be zero",
    ),
    Kind(
        "mixed_equations",
        r"Your equation holds along the motion, but it is not the equation for",
        "a combination of several coordinates' equations",
    ),
    Kind(
        "inertia_term",
        r"Every other term of your equation is right",
        "every force term right, the inertia (q̈) term wrong",
    ),
    Kind("unsolved", r"Your .* (still )?contains ", "an acceleration still holds another q̈"),
    Kind(
        "includes_potential_force",
        r"Your answer includes (the conservative part|\$\+\\partial V)",
        "Q_j holds −∂V/∂q_j (gravity, springs), which V already has",
    ),
    Kind(
        "up_to_total_derivative",
        r"Your L differs from T − V by a total time derivative",
        "L plus a total time derivative: same equations, not T − V",
    ),
    Kind(
        "time_function",
        r"Your L falls short of T − V by a function of t only",
        "L differs from T − V by a function of time only",
    ),
    Kind(
        "shifted_datum",
        r"In this scene .* is measured from",
        "a spring's stretch taken from the wrong origin",
    ),
    Kind("small_angle", r"This is the small-angle approximation", "linearised: sin θ ≈ θ"),
    Kind(
        "rounding",
        r"(Your answer is almost, but not exactly|Every term is almost, but not exactly)",
        "a number rounded or typed with a slip",
    ),
    Kind("swapped_parameters", r".* and .* are swapped", "two parameters swapped"),
    Kind("q_qdot_mixup", r"You mixed up", "a coordinate and its rate mixed up"),
    Kind(
        "rotation_term",
        r"(The rotation's|.*missing: a rigid body's T)",
        "a rigid body's ½ I ω² wrong or missing",
    ),
    Kind("squared", r"This is ω², not ω", "a frequency's square (ω² for ω)"),
    Kind("hertz", r"This is the frequency f = ω/2π", "f = ω/2π in hertz for the angular ω"),
    Kind("negated", r"Sign error: your answer is the negative", "the whole answer's sign"),
    Kind("sign_error", r"Sign error in", "one term's sign"),
    Kind(
        "wrong_factor",
        r"(Off by a factor|(Your term|The term) .* (is off by a factor|has the coefficient))",
        "a term (or the whole) off by a factor",
    ),
    Kind(
        "missing_potential",
        r"(Your V is not all of it|Your L is (T alone|not T − V)|Your equation leaves out|"
        r"Your .* is the acceleration without)",
        "a weight's or a spring's potential (or its force) left out",
    ),
    Kind("missing_term", r"Missing term", "a term is missing"),
    Kind("extra_term", r"Extra term", "a term that does not belong"),
    Kind("wrong_term", r"You have .* where .* belongs", "a term in place of another"),
    Kind(
        "wrong_units",
        r"(The term .* mixes units|The term .* cannot belong here|Your . differs from the "
        r"derived one by a constant)",
        "a term with the wrong units",
    ),
    Kind(
        "tiny_difference",
        r"Your answer differs from the derived result",
        "differs by a term too small to see at the samples",
    ),
    Kind("wrong", r"", "not equal to the key; nothing more specific was found"),
)
#: Outcomes not from a verdict: the answer does not parse; the checker ran out of budget.
UNREADABLE = "unreadable"
CANNOT_DECIDE = "cannot_decide"
EXTRA_KINDS = {
    UNREADABLE: "the answer does not parse (no attempt used)",
}
_COMPILED = [(k, re.compile(k.pattern)) for k in KINDS]
CREDIT = frozenset(k.name for k in KINDS if k.credit)


def code(quantity: str, kind: str) -> str:
    return f"{PREFIX[quantity]}.{kind}"


def kinds_of(correct: bool, feedback: list[str]) -> list[str]:
    """Every kind the verdict shows, most decisive first (the report counts the first)."""
    found = []
    for kind, pattern in _COMPILED:
        if kind.credit and not correct:
            continue
        if kind.name == "wrong":
            continue
        if any(pattern.match(line) for line in feedback):
            found.append(kind.name)
    if not found:
        found.append("correct" if correct else "wrong")
    return found


def outcome(quantity: str, correct: bool, feedback: list[str]) -> tuple[str, list[str]]:
    """The verdict's outcome code and all its codes: (``eom.sign_error``, [...])."""
    kinds = kinds_of(correct, feedback)
    return code(quantity, kinds[0]), [code(quantity, k) for k in kinds]


def meaning(code_: str) -> str:
    """The parameter-free description of an outcome code (``T.missing_term``: "a term is
    missing"): what a student of an open graded part is told, since it holds no expression of
    the key (the checker's own feedback names the missing term, i.e. gives the key away)."""
    kind = code_.split(".", 1)[-1]
    if kind in EXTRA_KINDS:
        return EXTRA_KINDS[kind]
    row = next((k for k in KINDS if k.name == kind), None)
    return row.meaning if row is not None else "not equal to the key"


def open_feedback(code_: str, feedback: list[str], note: bool = True) -> list[str]:
    """What a student of an open graded part is told: the outcome's parameter-free description,
    and none of the checker's math (its "Missing term ..." is the key). Kept: a parse error (about
    the student's own text; the parser never sees the key) and the "Cannot decide, because ..."
    lines grading.py and the app write (no expression)."""
    kind = code_.split(".", 1)[-1]
    if kind == UNREADABLE:
        return list(feedback)
    lines = [meaning(code_).capitalize() + "."] if code_ else []
    lines += [f for f in feedback if f.startswith("Cannot decide, because")]
    if note and kind not in CREDIT:  # (PrairieLearn has its own answer panel: no note)
        lines.append("The checker's full feedback is shown once this part is closed.")
    return lines


def table() -> list[dict[str, str]]:
    """The documented table: kind, meaning, whether it scores the part in full."""
    rows = [{"kind": k.name, "meaning": k.meaning, "full_credit": k.credit} for k in KINDS]
    rows += [{"kind": n, "meaning": m, "full_credit": False} for n, m in EXTRA_KINDS.items()]
    return rows
