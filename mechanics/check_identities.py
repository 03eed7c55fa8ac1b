"""The checker's exact argument that an expression is identically zero (trig identities).

`mechanics.check.zero_proof` settles |·| and sign(), then hands each case here: a rational
function of sin and cos of the coordinates (and of parameters, t, q̇, q̈) is zero exactly when
its numerator is zero modulo sin² + cos² = 1, once every trig argument is a sum of integer
multiples of single symbols (expand_trig then writes sin(3θ) as a polynomial in sin θ, cos θ).

Half and other fractional angles are brought to that class by renaming the angle: where θ
appears as θ/2 (tan(θ/2) for sin θ/(1 + cos θ)), θ = 2u is put everywhere, a bijection of the
reals, so the expression is an identity in θ exactly when it is one in u, and there every
multiple is an integer (sin θ is sin 2u). No step guesses: a non-zero claim is as exact as a
zero one, and past the size budget the answer is None ("cannot tell").
"""

from __future__ import annotations

import math
import random

import sympy as sp

#: No normal form is tried past this size (count_ops); exact evaluation decides instead.
PROOF_OPS = 400
#: A normal form (expanded) is tried only up to this many terms of expansion ((sin θ + cos θ)⁶⁰
#: is 61 terms, and 15 s of trig passes); past it, exact evaluation decides alone.
MAX_NORMAL_TERMS = 40
#: expand_trig of sin(n θ) is a polynomial of degree n: past this n the trig stays opaque. It
#: bounds the multiples after a fractional angle is renamed too (θ/3 beside 3θ is 9u).
MAX_TRIG_MULTIPLE = 8

_TRIG = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)


def expansion_size(expr: sp.Expr, cap: int) -> int:
    """An upper estimate of how many terms expanding ``expr`` (products, integer powers of sums,
    trig of sums) gives, saturating past ``cap``: decided from the tree, without expanding."""
    if expr.is_Atom:
        return 1
    if isinstance(expr, sp.Add):
        return min(cap + 1, sum(expansion_size(a, cap) for a in expr.args))
    if isinstance(expr, sp.Mul):
        size = 1
        for a in expr.args:
            size = min(cap + 1, size * expansion_size(a, cap))
        return size
    if isinstance(expr, sp.Pow):
        n = expr.exp
        if not (n.is_Integer and n > 1):
            return 1  # (a + b)⁻² or √(a + b) stays one term
        k = expansion_size(expr.base, cap)
        return 1 if k == 1 else min(cap + 1, math.comb(int(min(n, 10**4)) + k - 1, k - 1))
    if isinstance(expr, sp.Function):
        k = max((expansion_size(a, cap) for a in expr.args), default=1)
        if k == 1:
            return 1  # sin θ stays one term (sin²θ + cos²θ to the 16th is 17 terms, not 20349)
        return min(cap + 1, 2 ** min(k, 20))  # sin(a + b + …) expands into products
    return 1


def integer_angles(e: sp.Expr) -> sp.Expr:
    """``e`` with every symbol that a trig argument holds with a fractional coefficient renamed
    so that none does: θ → 2u where θ/2 appears, θ → 6u where θ/2 and θ/3 do (a fresh symbol
    with θ's assumptions). θ = D u is a bijection of the reals (of the positive reals for a
    positive θ), so ``e`` is identically zero exactly when the result is. Left as it is when
    a denominator is past MAX_TRIG_MULTIPLE (sin(θ/100) is sin of 100 times nothing short)."""
    denominators: dict[sp.Symbol, int] = {}
    for f in e.atoms(*_TRIG):
        for term in sp.Add.make_args(sp.expand(f.args[0])):
            number, rest = term.as_coeff_Mul()
            if rest.is_Symbol and number.is_Rational and not number.is_Integer:
                denominators[rest] = math.lcm(denominators.get(rest, 1), int(number.q))
    if not denominators or max(denominators.values()) > MAX_TRIG_MULTIPLE:
        return e
    renamed = {x: n * sp.Dummy(x.name, **x.assumptions0) for x, n in denominators.items()}
    return e.xreplace(renamed)


def zero_by_algebra(e: sp.Expr, normal_form: bool = True) -> bool | None:
    """zero_proof's exact argument for a rational function of sin, cos and the symbols: its
    normal form when ``normal_form`` (small), else exact evaluation at random points."""
    e = integer_angles(e)
    e = e.replace(sp.tan, lambda a: sp.sin(a) / sp.cos(a))
    e = e.replace(sp.cot, lambda a: sp.cos(a) / sp.sin(a))
    e = e.replace(sp.sec, lambda a: 1 / sp.cos(a))
    e = e.replace(sp.csc, lambda a: 1 / sp.sin(a))
    for f in e.atoms(sp.sin, sp.cos):
        coefficients = sp.Add.make_args(f.args[0])
        for term in coefficients:
            number = term.as_coeff_Mul()[0]
            if not number.is_Integer or abs(number) > MAX_TRIG_MULTIPLE:
                return None  # sin(w t/2), sin(100 θ): no short polynomial in sin θ, cos θ
    e = sp.expand_trig(e)
    pairs: dict[sp.Expr, tuple[sp.Symbol, sp.Symbol]] = {}
    opaque = False  # sin(w t): still on the circle, but not shown independent of the rest
    for f in sorted(e.atoms(sp.sin, sp.cos), key=sp.default_sort_key):
        a = f.args[0]
        if a.is_number:
            continue  # cos 1: a number
        opaque = opaque or not a.is_Symbol
        pairs.setdefault(a, (sp.Dummy("s", real=True), sp.Dummy("c", real=True)))
    e = e.xreplace(
        {k: v for a, (s, c) in pairs.items() for k, v in ((sp.sin(a), s), (sp.cos(a), c))}
    )
    if not e.is_rational_function(*e.free_symbols):
        return None  # exp, log, a square root of a variable, ...
    if (
        not normal_form
        or sp.count_ops(e) > PROOF_OPS
        or expansion_size(e, MAX_NORMAL_TERMS) > MAX_NORMAL_TERMS  # sin 8θ is 5 terms now
    ):
        zero = zero_at_random_points(e, pairs)
    else:
        numerator, denominator = sp.fraction(sp.together(e))
        if reduce_circle(denominator, pairs) == 0:
            return None  # no value anywhere: not an identity to speak of
        zero = reduce_circle(numerator, pairs) == 0
    # zero with sin(w t), cos(w t) as free points on the circle is zero; non-zero is only
    # non-zero if nothing ties sin(w t) to the rest (cos(2 w t) would): claimed no further
    return None if zero is False and opaque else zero


def zero_at_random_points(e: sp.Expr, pairs: dict) -> bool | None:
    """A rational function too big to bring to normal form, evaluated exactly (rational
    arithmetic, no rounding) at random rational points, sin and cos of each coordinate on the
    unit circle ((1 − u²)/(1 + u²), 2u/(1 + u²)). A non-zero value is an exact certificate that
    it is not zero; zero at every point means it is zero but for a chance below
    degree/2⁴⁸ per point (Schwartz–Zippel): a rational function has no narrow bumps to hide in.
    """
    rng = random.Random(2)
    circle = {s for pair in pairs.values() for s in pair}
    symbols = sorted(e.free_symbols - circle, key=sp.default_sort_key)
    zeros = 0
    for _ in range(4):
        point: dict[sp.Expr, sp.Expr] = {
            x: sp.Rational(rng.randrange(1, 2**48), rng.randrange(1, 2**16)) for x in symbols
        }
        for s, c in pairs.values():
            u = sp.Rational(rng.randrange(1, 2**48), 2**48)
            point[s], point[c] = 2 * u / (1 + u**2), (1 - u**2) / (1 + u**2)
        try:
            value = e.xreplace(point)
        except ZeroDivisionError:
            continue
        if not value.is_Rational:
            continue  # a pole (zoo, nan) at this point: no number there
        if value != 0:
            return False
        zeros += 1
    return True if zeros >= 2 else None


def reduce_circle(p: sp.Expr, pairs: dict) -> sp.Expr:
    """p with every sin² written 1 − cos²: the normal form modulo sin² + cos² = 1."""
    p = sp.expand(p)
    for s, c in pairs.values():
        p = sp.expand(
            p.replace(
                lambda x, s=s: x.is_Pow and x.base == s and x.exp.is_Integer and x.exp > 1,
                lambda x, s=s, c=c: s ** (x.exp % 2) * (1 - c**2) ** (x.exp // 2),
            )
        )
    return p
