"""Is a wrong answer the small-angle approximation of the right one? (the checker's rule)

An approximation is claimed only where the student's answer is the derived result with
sin x ≈ x, tan x ≈ x, cos x ≈ 1 (or 1 − x²/2) *and still keeps every term so approximated*.
The pendulum's L = ½ m l² θ̇² is the derived L with m g l cos θ replaced by m g l, a constant
that moves no motion: the term is gone, not approximated, and calling it "cos θ ≈ 1" hid a
forgotten V (issue 23, item 7a). A term whose approximation is free of the motion (a constant
in V or L, where constants are only the datum) or zero is a dropped term, and no approximation
is claimed for it; `mechanics.check_potential` names a dropped potential for what it is.

The functions take the checker's judge (`mechanics.check._Judge`): its quantity, model and
canonical forms.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from mechanics.check_identities import PROOF_OPS
from mechanics.expr import to_latex
from mechanics.steps import _symbols_for


def small_angle(
    judge: Any,
    given: sp.Expr,
    expected: sp.Expr,
    subject: str = "This is the small-angle approximation of the right answer",
) -> str:
    """A sentence when the answer is the derived result with sin x ≈ x, cos x ≈ 1 (or
    1 − x²/2), tan x ≈ x: an approximation, valid only near the angles' zero, not a slip.

    Judged group by group of velocity monomials (T's cross term may be cos(θ₁ − θ₂) ≈ 1
    while V keeps its cos θ₁ exact, or takes 1 − θ₁²/2), each match proved, not sampled; ""
    when a group does not match, or when a term the match needs is dropped rather than kept."""
    from mechanics.check import MAX_TERMS, _tidy, constant_proof, inline, zero_proof

    m = judge.m
    if judge.quantity == "accel":
        return ""  # a quotient has no velocity groups to speak of: linearised reads it
    g, e = judge._canonical(given), judge._canonical(expected)
    if len(g) + len(e) > MAX_TERMS:
        return ""
    datum = judge.quantity in ("V", "L")
    if datum:  # the datum: 1 − θ²/2 may come without its 1
        g, e = {k: v for k, v in g.items() if k != 1}, {k: v for k, v in e.items() if k != 1}
    used: dict[sp.Expr, sp.Expr] = {}
    for velocity in dict.fromkeys([*map(judge._velocity, e), *map(judge._velocity, g)]):
        mine = sp.Add(*(c * k for k, c in g.items() if judge._velocity(k) == velocity))
        theirs = _tidy(sp.Add(*(c * k for k, c in e.items() if judge._velocity(k) == velocity)), m)
        if zero_proof(mine - theirs, m) is True:
            continue
        same = zero_proof
        if datum and velocity == 1:
            same = constant_proof  # −m g l (1 − θ²/2) and m g l θ²/2 are one datum apart
        for order in (1, 2):
            approximate, replaced = approximate_trig(m, theirs, order)
            if replaced and same(mine - approximate, m) is True:
                if dropped(m, theirs, replaced, datum):
                    return ""  # cos θ ≈ 1 made m g l cos θ a constant: a term left out
                used.update(replaced)
                break
        else:
            return ""
    if not used:
        return ""
    angles = sorted({q for atom in used for q in m.q if atom.has(q)}, key=m.q.index)
    where = " = ".join([*(inline(q)[1:-1] for q in angles), "0"])
    atoms = sorted(used, key=sp.default_sort_key)
    taken = ", ".join(f"${to_latex(a)} \\approx {to_latex(used[a])}$" for a in atoms)
    kept = ", ".join(inline(a) for a in atoms)
    return (
        f"{subject} ({taken}): valid only "
        f"for small swings, near ${where}$, not in general. The exact answer keeps "
        f"{kept}."
    )


def dropped(m: Any, theirs: sp.Expr, replaced: dict, datum: bool) -> bool:
    """Does the approximation leave nothing of some term of ``theirs``: zero, or (in V and L,
    where a constant is only the datum) free of the motion? Then the student did not keep that
    term in an approximate form; they left it out."""
    motion = (*m.q, *m.qd, *m.qdd)
    for term in sp.Add.make_args(sp.expand(theirs)):
        if not term.has(*replaced):
            continue
        approximate = sp.expand(term.xreplace(replaced))
        if approximate == 0 or (datum and not approximate.has(*motion)):
            return True
    return False


def linearised(judge: Any, given: sp.Expr, expected: sp.Expr) -> str:
    """A sentence when the answer is the derived result's Taylor polynomial at rest in the
    angles: to first order in q, q̇, q̈ for an equation, q̈ or Q (the linearised equation,
    where sin(θ₁ − θ₂) θ̇₂² is second order and goes), to second order in q, q̇ for T, V, L.
    The match is proved; "" if there is none."""
    from mechanics.check import MAX_TERMS, constant_proof, inline, zero_proof

    m = judge.m
    trig = [f for f in expected.atoms(sp.sin, sp.cos, sp.tan) if f.args[0].has(*m.q)]
    angles = [q for q in m.q if any(f.has(q) for f in trig)]
    if not angles or sp.count_ops(expected) > PROOF_OPS:
        return ""
    g, e = judge._canonical(given), judge._canonical(expected)
    if len(g) + len(e) > MAX_TERMS or set(g) <= set(e):
        return ""  # nothing approximated, only terms left out: 'Missing term' says it
    energy = judge.quantity in ("T", "V", "L")
    to_sym, back = _symbols_for(m)
    small = [to_sym[x] for x in (*angles, *m.qd, *([] if energy else m.qdd))]
    eps = sp.Dummy("eps")
    scaled = expected.xreplace(to_sym).xreplace({x: eps * x for x in small})
    taylor, term = sp.S.Zero, scaled
    for k in range(3 if energy else 2):
        taylor += term.subs(eps, 0) / sp.factorial(k)
        term = term.diff(eps)
    taylor = taylor.xreplace(back)
    if energy and not _keeps_every_term(judge, taylor, e):
        return ""  # ½ m l² sin²θ φ̇² gone whole: a term left out, not approximated
    same = constant_proof if judge.quantity in ("V", "L") else zero_proof
    if same(given - taylor, m) is not True or same(expected - taylor, m) is True:
        return ""
    where = " = ".join([*(inline(q)[1:-1] for q in angles), "0"])
    kept = ", ".join(inline(f) for f in sorted(trig, key=sp.default_sort_key))
    order = "to second order" if energy else "the linearised equation: to first order"
    return (
        f"This is the small-angle approximation of the right answer ({order} in the angles "
        f"and their rates): valid only for small swings, near ${where}$, not in general. "
        f"The exact answer keeps {kept}."
    )


def _keeps_every_term(judge: Any, taylor: sp.Expr, expected: dict[sp.Expr, sp.Expr]) -> bool:
    """Does the Taylor polynomial of T, V or L keep something of each velocity group of the
    derived result (of the group free of rates, something that is not a constant)? The
    spherical pendulum's ½ m l² sin²θ φ̇² is of fourth order and leaves nothing: an answer
    without it has left a term out, which 'Missing term' says."""
    kept = {judge._velocity(k) for k in judge._canonical(taylor) if k != 1}
    return {judge._velocity(k) for k in expected if k != 1} <= kept


def approximate_trig(m: Any, e: sp.Expr, order: int) -> tuple[sp.Expr, dict[sp.Expr, sp.Expr]]:
    """``e`` with sin, cos, tan of the coordinates replaced by their Taylor polynomials at
    0: sin x ≈ x, tan x ≈ x, and cos x ≈ 1 (order 1) or 1 − x²/2 (order 2)."""
    replaced: dict[sp.Expr, sp.Expr] = {}
    for f in e.atoms(sp.sin, sp.cos, sp.tan):
        x = f.args[0]
        if not any(x.has(q) for q in m.q):
            continue  # cos(w t): no angle to be small
        if isinstance(f, sp.cos):
            replaced[f] = sp.S.One if order == 1 else 1 - x**2 / 2
        else:
            replaced[f] = x
    return e.xreplace(replaced), replaced
