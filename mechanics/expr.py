"""The whitelist parser (plain text -> sympy) and the printers (sympy -> plain text / LaTeX).

User text reaches sympy only through `parse`: Python's own tokenizer/AST reads the text, and a walk
over the tree admits numbers, declared names, + - * / **, and a fixed list of functions —
nothing else is ever evaluated. Sizes, depth and exponents are capped before any algebra runs, so
hostile input (``9**9**9**9``, 100 kB strings, deep nesting) is refused in microseconds.
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Callable, Mapping
from fractions import Fraction

import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.physics.vector.printing import vlatex
from sympy.printing.str import StrPrinter

MAX_LENGTH = 2000
MAX_DEPTH = 32
MAX_EXPONENT = 64
MAX_DIGITS = 30

FUNCTIONS: Mapping[str, Callable] = {
    "sin": sp.sin,
    "cos": sp.cos,
    "tan": sp.tan,
    "cot": sp.cot,
    "sec": sp.sec,
    "csc": sp.csc,
    "asin": sp.asin,
    "acos": sp.acos,
    "atan": sp.atan,
    "atan2": sp.atan2,
    "sinh": sp.sinh,
    "cosh": sp.cosh,
    "tanh": sp.tanh,
    "exp": sp.exp,
    "log": sp.log,
    "sqrt": sp.sqrt,
    "abs": sp.Abs,
    "sign": sp.sign,
}
_ARITY = {"atan2": 2}
CONSTANTS: Mapping[str, sp.Expr] = {"pi": sp.pi}

_ALLOWED_CHARS = re.compile(r"[A-Za-z0-9_+\-*/().,\s]")
_BINOPS = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a**b,
}
_NOT_ALLOWED = {
    ast.Attribute: "attribute access is not allowed",
    ast.Lambda: "lambda is not allowed",
    ast.Subscript: "subscripts are not allowed",
    ast.Compare: "comparisons are not allowed",
    ast.BoolOp: "'and'/'or' are not allowed",
    ast.BitXor: "'^' is not allowed; write powers as **",
}


class ExprError(ValueError):
    """An expression that is not in the plain-text convention; names the field it came from."""

    def __init__(self, message: str, *, field: str = "", position: int | None = None) -> None:
        self.field, self.message, self.position = field, message, position
        super().__init__(f"{field}: {message}" if field else message)


def _number(value: int | float | Fraction, field: str) -> sp.Expr:
    if isinstance(value, bool):
        raise ExprError("true/false is not a number", field=field)
    if isinstance(value, int):
        if len(str(abs(value))) > MAX_DIGITS:
            raise ExprError("number too large", field=field)
        return sp.Integer(value)
    if not math.isfinite(value):
        raise ExprError("not a finite number", field=field)
    # Short decimals become exact rationals, so 0.5*m*v**2 prints as m*v**2/2.
    text = repr(value)
    if len(text.replace("-", "").replace(".", "").lstrip("0")) <= 6 and "e" not in text:
        return sp.Rational(text)
    return sp.Float(value, 15)


def _precheck(text: str, field: str) -> str:
    if not isinstance(text, str):
        raise ExprError("expected text or a number", field=field)
    if len(text) > MAX_LENGTH:
        raise ExprError(f"expression longer than {MAX_LENGTH} characters", field=field)
    depth = 0
    for i, ch in enumerate(text):
        if not _ALLOWED_CHARS.match(ch):
            if ch == "^":
                raise ExprError("'^' is not allowed; write powers as **", field=field, position=i)
            raise ExprError(f"character {ch!r} is not allowed", field=field, position=i)
        if ch == "(":
            depth += 1
            if depth > MAX_DEPTH:
                raise ExprError(f"nested deeper than {MAX_DEPTH}", field=field, position=i)
        elif ch == ")":
            depth -= 1
    if "__" in text:
        raise ExprError("names with '__' are not allowed", field=field, position=text.index("__"))
    text = text.strip()
    if not text:
        raise ExprError("empty expression", field=field)
    return text


def _tree(text: str, field: str) -> ast.expr:
    try:
        return ast.parse(text, mode="eval").body
    except SyntaxError as exc:
        col = (exc.offset or 1) - 1
        raise ExprError(f"syntax error at character {col}", field=field, position=col) from None
    except (RecursionError, MemoryError, ValueError):
        raise ExprError("expression too complex", field=field) from None


def parse(text: str | int | float, names: Mapping[str, sp.Expr], *, field: str = "") -> sp.Expr:
    """Plain text (or a number) -> sympy, admitting only the whitelist and the given names."""
    if isinstance(text, int | float):
        return _number(text, field)
    tree = _tree(_precheck(text, field), field)

    def walk(node: ast.AST, depth: int) -> sp.Expr:
        if depth > MAX_DEPTH:
            raise ExprError(f"nested deeper than {MAX_DEPTH}", field=field)
        pos = getattr(node, "col_offset", None)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, int | float) and not isinstance(node.value, bool):
                return _number(node.value, field)
            raise ExprError(
                f"{type(node.value).__name__} literals are not allowed", field=field, position=pos
            )
        if isinstance(node, ast.Name):
            if node.id in names:
                return names[node.id]
            if node.id in CONSTANTS:
                return CONSTANTS[node.id]
            if node.id in FUNCTIONS:
                raise ExprError(f"function '{node.id}' needs arguments", field=field, position=pos)
            known = sorted(names)
            hint = f" (known: {', '.join(known[:12])}{', ...' if len(known) > 12 else ''})"
            raise ExprError(f"unknown name '{node.id}'{hint}", field=field, position=pos)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            value = walk(node.operand, depth + 1)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
            left = walk(node.left, depth + 1)
            right = walk(node.right, depth + 1)
            if isinstance(node.op, ast.Pow):
                _check_power(left, right, field, pos)
            if isinstance(node.op, ast.Div) and right == 0:
                raise ExprError("division by zero", field=field, position=pos)
            result = _BINOPS[type(node.op)](left, right)
            if result.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
                raise ExprError("not a finite number", field=field, position=pos)
            return result
        if isinstance(node, ast.Call):
            return call(node, depth)
        for kind, message in _NOT_ALLOWED.items():
            if isinstance(node, kind) or isinstance(getattr(node, "op", None), kind):
                raise ExprError(message, field=field, position=pos)
        raise ExprError(f"{type(node).__name__} is not allowed", field=field, position=pos)

    def call(node: ast.Call, depth: int) -> sp.Expr:
        pos = node.col_offset
        if not isinstance(node.func, ast.Name):
            raise ExprError("only the listed functions may be called", field=field, position=pos)
        name = node.func.id
        if name not in FUNCTIONS:
            raise ExprError(
                f"function '{name}' is not allowed (allowed: {', '.join(FUNCTIONS)})",
                field=field,
                position=pos,
            )
        if node.keywords:
            raise ExprError(f"{name}() takes no keyword arguments", field=field, position=pos)
        arity = _ARITY.get(name, 1)
        if len(node.args) != arity or any(isinstance(a, ast.Starred) for a in node.args):
            raise ExprError(
                f"{name}() takes {arity} argument{'s' if arity > 1 else ''}",
                field=field,
                position=pos,
            )
        result = FUNCTIONS[name](*(walk(a, depth + 1) for a in node.args))
        if result.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
            raise ExprError("not a finite number", field=field, position=pos)
        return result

    return walk(tree, 0)


def _check_power(base: sp.Expr, exponent: sp.Expr, field: str, pos: int | None) -> None:
    """Refuse powers that would take sympy minutes or memory: big numeric exponents."""
    if exponent.is_number:
        if _magnitude(exponent) > MAX_EXPONENT:
            raise ExprError(f"exponent larger than {MAX_EXPONENT}", field=field, position=pos)
    elif not exponent.free_symbols and exponent.atoms(sp.Function):
        raise ExprError("exponent too complex", field=field, position=pos)
    if base.is_number and exponent.is_number and base != 0:
        if abs(_magnitude(exponent) * math.log10(_magnitude(base, 5) or 1)) > 300:
            raise ExprError("number too large", field=field, position=pos)


def _magnitude(value: sp.Expr, digits: int = 15) -> float:
    """|value| of a number, complex ones too (sqrt(-1)); inf when it overflows a float."""
    try:
        return abs(complex(value.evalf(digits)))
    except (TypeError, OverflowError):
        return math.inf


def free_names(text: str) -> set[str]:
    """Identifiers the text uses (not function names or pi), after the same safety checks."""
    tree = _tree(_precheck(text, ""), "")
    return (
        {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)} - set(FUNCTIONS) - set(CONSTANTS)
    )


class _PlainPrinter(StrPrinter):
    """sympy's str printer, with q(t) -> q, q̇ -> q_dot, Abs -> abs: parseable by `parse`."""

    def _print_Function(self, expr: sp.Expr) -> str:
        if isinstance(expr, AppliedUndef):
            return expr.func.__name__
        if isinstance(expr, sp.Abs):
            return f"abs({self._print(expr.args[0])})"
        return super()._print_Function(expr)

    def _print_Abs(self, expr: sp.Expr) -> str:
        return f"abs({self._print(expr.args[0])})"

    def _print_Derivative(self, expr: sp.Derivative) -> str:
        base = expr.expr
        order = sum(count for _, count in expr.variable_count)
        if isinstance(base, AppliedUndef) and order in (1, 2):
            return f"{base.func.__name__}_{'d' * (order - 1)}dot"
        return super()._print_Derivative(expr)

    def _print_Float(self, expr: sp.Float) -> str:
        value = float(expr)
        return repr(int(value)) + ".0" if value.is_integer() and abs(value) < 1e15 else repr(value)

    def _print_Exp1(self, expr: sp.Expr) -> str:
        return "exp(1)"


_PLAIN = _PlainPrinter({"order": None})


def to_plain(expr: sp.Expr | list) -> str:
    """sympy -> plain text in the project's convention (round-trips through `parse`)."""
    if isinstance(expr, list):
        return "[" + ", ".join(to_plain(e) for e in expr) + "]"
    return _PLAIN.doprint(expr)


def to_latex(expr: sp.Expr) -> str:
    """Textbook LaTeX: dot notation for time derivatives, Greek names as letters."""
    return vlatex(expr)
