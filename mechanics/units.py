"""Dimensions of the scene's symbols, so the checker can tell a term that is not an energy.

A dimension is a vector of exponents of (mass, length, time). Unit strings come from the scene
specs (`units = { m = "kg", g = "m/s^2" }`) and are read by a tiny grammar of their own: products
and quotients of known units with integer powers; nothing is evaluated.
"""

from __future__ import annotations

import re

import sympy as sp

Dim = tuple[int, int, int]  # (M, L, T)

NONE: Dim = (0, 0, 0)
ENERGY: Dim = (1, 2, -2)

BASE: dict[str, Dim] = {
    "1": NONE,
    "rad": NONE,
    "kg": (1, 0, 0),
    "m": (0, 1, 0),
    "s": (0, 0, 1),
    "N": (1, 1, -2),
    "J": ENERGY,
    "W": (1, 2, -3),
    "Hz": (0, 0, -1),
}

_TOKEN = re.compile(r"\s*(?:(?P<unit>[A-Za-z]+|1)(?:\^(?P<pow>-?\d+))?|(?P<op>[*/]))")


class UnitError(ValueError):
    pass


def parse_unit(text: str) -> Dim:
    """'N*m^2/kg^2' -> (-1, 3, -2); every factor after '/' is divided."""
    dim = [0, 0, 0]
    sign = 1
    pos = 0
    text = text.strip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise UnitError(f"cannot read unit {text!r} at {pos}")
        pos = m.end()
        if m["op"]:
            sign = -1 if m["op"] == "/" else sign
            continue
        if m["unit"] not in BASE:
            raise UnitError(f"unknown unit {m['unit']!r} in {text!r}")
        power = int(m["pow"] or 1) * sign
        for i, e in enumerate(BASE[m["unit"]]):
            dim[i] += e * power
    return tuple(dim)


def fmt(dim: Dim) -> str:
    """(1, 2, -2) -> 'kg·m²/s²' for feedback a student reads."""
    sup = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
    top, bottom = [], []
    for name, e in zip(("kg", "m", "s"), dim, strict=True):
        if e:
            part = name + (str(abs(e)).translate(sup) if abs(e) != 1 else "")
            (top if e > 0 else bottom).append(part)
    if not (top or bottom):
        return "dimensionless"
    below = "·".join(bottom) if len(bottom) < 2 else f"({'·'.join(bottom)})"  # 1/(m·s²)
    return ("·".join(top) or "1") + ("/" + below if bottom else "")


def dimension(expr: sp.Expr, dims: dict[sp.Expr, Dim]) -> Dim | None:
    """The dimension of a term, or None where it has none consistently (a sum of mixed terms)."""
    if expr.is_number:
        return NONE
    if expr in dims:
        return dims[expr]
    if expr.is_Mul:
        total = [0, 0, 0]
        for f in expr.args:
            d = dimension(f, dims)
            if d is None:
                return None
            total = [a + b for a, b in zip(total, d, strict=True)]
        return tuple(total)
    if expr.is_Pow:
        base = dimension(expr.base, dims)
        if base is None or not expr.exp.is_Rational:
            return None if base != NONE else NONE
        scaled = [b * expr.exp for b in base]
        if not all(sp.Rational(x).is_integer for x in scaled):
            return None
        return tuple(int(x) for x in scaled)
    if expr.is_Add:
        found = {dimension(a, dims) for a in expr.args}
        return found.pop() if len(found) == 1 else None
    if isinstance(expr, sp.Abs):
        return dimension(expr.args[0], dims)
    if isinstance(expr, sp.sign):
        return NONE
    if isinstance(expr, sp.Function):  # sin, exp, ...: arguments must be dimensionless
        return NONE if all(dimension(a, dims) == NONE for a in expr.args) else None
    return None
