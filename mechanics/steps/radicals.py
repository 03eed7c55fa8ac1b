"""The textbook form of a piece with roots of sums in it (a gravitational potential
−G M m/√((x − a)² + y²), a spring's length √(x² + y²)): why a separate pass.

tidy()'s trig pass is made for polynomials in q, q̇ and sin/cos of the angles. Handed a root of a
sum it expands the sum under the root, puts everything over one denominator (factor) and
differentiates that quotient in the next step: the restricted three-body problem's f grew from
140 to 3,300 operations and took seconds per piece. Here each root of a sum (a power with a
fractional exponent: −1/2, −3/2, 1/2) is held as one symbol while the rest is expanded, grouped by
velocity monomial and by that symbol, and each group's polynomial coefficient gets the ordinary
trig pass: the terms of the potential stay as they were written, one per attracting body.

An integer inverse power of a sum, 1/(m₁ + m₂) or 1/(M + m sin²θ), is NOT held: putting it over
one denominator with the rest is the simplification the reader wants. Held, the Atwood rope's
force stayed g m₁ ((m₂ − m₁)/(m₁ + m₂) + 1) instead of 2 g m₁ m₂/(m₁ + m₂), and the ladder's
contact geometry kept 1/(sin²θ + cos²θ), so its two normal forces were not found.

No built-in scene has a root of a sum in any piece it tidies (derivation or Newton's panel), so
their output is unchanged by this pass.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp


def radicals(expr: sp.Expr) -> list[sp.Pow]:
    """The powers of a sum with a non-integer exponent (roots), outermost only, in a fixed order
    (the symbols standing for them must not depend on hashing). Integer inverse powers are left
    to the ordinary pass, which cancels them (see the module docstring)."""
    found: set[sp.Pow] = set()

    def walk(e: sp.Expr) -> None:
        if e.is_Pow and e.base.is_Add and not e.exp.is_integer:
            found.add(e)
            return
        for a in e.args:
            walk(a)

    walk(expr)
    return sorted(found, key=sp.default_sort_key)


def tidy_radical(
    expr: sp.Expr,
    roots: list[sp.Pow],
    velocities: tuple,
    trig_pass: Callable[[sp.Expr], tuple[sp.Expr, tuple]],
    size: Callable[[sp.Expr], tuple[int, int]],
    factor_whole: bool,
) -> tuple[sp.Expr, tuple]:
    """tidy() of an expression with ``roots`` in it (see the module docstring): returns the tidied
    expression and the pieces left unsimplified, like steps._tidy_symbols."""
    held = {r: sp.Symbol(f"_root{i}") for i, r in enumerate(roots)}
    back = {s: r for r, s in held.items()}
    e = sp.expand(expr.xreplace(held))
    if e == 0:
        return e, ()
    stand_ins = set(back)
    groups: dict[tuple[sp.Expr, sp.Expr], list[sp.Expr]] = {}
    for term in sp.Add.make_args(e):
        velocity, root, rest = [], [], []
        for f in sp.Mul.make_args(term):
            if f.free_symbols & stand_ins:
                root.append(f)
            elif velocities and f.free_symbols & set(velocities):
                velocity.append(f)
            else:
                rest.append(f)
        groups.setdefault((sp.Mul(*velocity), sp.Mul(*root)), []).append(sp.Mul(*rest))
    total, skipped = [], []
    for (velocity, root), coefficients in groups.items():
        coefficient, flags = trig_pass(sp.Add(*coefficients))
        skipped.extend(flags)
        total.append(coefficient * velocity * root)
    out = sp.Add(*total)
    if factor_whole:  # on the stand-ins: factor_terms also works inside every root, for seconds
        out = min((out, sp.factor_terms(out)), key=lambda x: size(x.xreplace(back)))
    return out.xreplace(back), tuple(skipped)


def held(exprs: list[sp.Expr]) -> tuple[dict[sp.Pow, sp.Symbol], dict[sp.Symbol, sp.Pow]]:
    """Each root of a sum in ``exprs`` as a symbol, and back: determinants and cancel() work on
    polynomials fast, and on the roots themselves (dotprodsimp, together) for seconds."""
    roots = sorted({r for e in exprs for r in radicals(e)}, key=sp.default_sort_key)
    to = {r: sp.Symbol(f"_root{i}") for i, r in enumerate(roots)}
    return to, {s: r for r, s in to.items()}
