"""Which conditions at rest sympy's solver is asked to solve in closed form.

The numeric search finds the roots whatever sympy does; sympy only adds closed forms. Where a
condition has none, asking costs a request its budget: an inverted pendulum on a torsion spring
(k θ = m g l sin θ) spent 66 s of a 67 s answer in sympy's Lambert-W and bivariate tries, which
end in "no closed form" (issue 23, item 8).
"""

from __future__ import annotations

from typing import Any

from sympy import Add, Dummy, Mul, Pow, factor_terms
from sympy.core.function import AppliedUndef


def mixes_trig(expr: Any, trig: tuple) -> bool:
    """Does a coordinate (an applied function q(t)) enter one additive factor of ``expr`` both
    inside a trigonometric function and outside every one (k θ − m g l sin θ)? Such a
    condition is transcendental: sympy's solver spends a minute in its Lambert-W and bivariate
    tries (66 s of an inverted pendulum on a torsion spring) before it gives up. A product
    (θ sin θ) is not one: each factor alone is polynomial or trigonometric."""
    for factor in Mul.make_args(factor_terms(expr)):
        base = factor.base if isinstance(factor, Pow) else factor
        if not isinstance(base, Add):
            continue
        trigs = base.atoms(*trig)
        outside = base.xreplace({f: Dummy() for f in trigs}).atoms(AppliedUndef)
        inside = set().union(*(f.atoms(AppliedUndef) for f in trigs)) if trigs else set()
        if outside & inside:
            return True
    return False


def rational_in_coordinates(expr: Any) -> bool:
    """Is ``expr`` a rational function of the coordinates (the applied functions q(t) in it),
    whatever the parameters do? Two conditions with a radical of the coordinates (the
    restricted three-body problem's 1/√((x + μ)² + y²)) kept sympy's solver 10 s to minutes
    before it said it could not; polynomial and rational ones it settles or refuses quickly."""
    coordinates = sorted(expr.atoms(AppliedUndef), key=str)
    if not coordinates:
        return True
    symbols = [Dummy() for _ in coordinates]
    plain = expr.xreplace(dict(zip(coordinates, symbols, strict=True)))
    return bool(plain.is_rational_function(*symbols))
