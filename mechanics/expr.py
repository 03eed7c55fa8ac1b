"""The whitelist parser (plain text -> sympy) and the printers (sympy -> plain text / LaTeX).

User text reaches sympy only through `parse`: Python's own parser reads the text into a syntax
tree, and a walk over that tree admits numbers, the caller's names, + - * / **, and a fixed list of
functions — nothing is ever executed. Length, nesting, digits and exponents are capped before any
algebra runs, so hostile input (``9**9**9**9``, 100 kB strings, deep nesting) fails in
microseconds instead of tying up a server worker.

Decimals: a literal with an integral value below 1e15 (``2.0``, ``1e6``) becomes an Integer; one
with at most 6 significant digits and size in [1e-6, 1e30) becomes an exact Rational (``0.5`` ->
1/2, ``9.81`` -> 981/100) so derivations print as textbooks do (``m*g*l/2``); any other decimal
stays a 15-digit ``sympy.Float``. Python ints and floats handed to `parse` follow the same rules.
"""

from __future__ import annotations

import ast
import difflib
import functools
import keyword
import math
import operator
import re
import string
import sys
from collections.abc import Callable, Mapping
from decimal import Decimal
from fractions import Fraction
from types import MappingProxyType

import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.physics.vector.printing import vlatex
from sympy.printing.str import StrPrinter

MAX_LENGTH = 2000
MAX_DEPTH = 32
MAX_EXPONENT = 64
#: The largest degree nested powers may reach: exponents multiply when powers nest
#: ((x**64)**64 is x**4096) and add when powers of one base multiply (x**64*x**64), so each
#: exponent under MAX_EXPONENT is not enough; an answer of mechanics is of degree 2 to 8.
MAX_DEGREE = 64
#: How deep exponentials may nest (exp, sinh, cosh, a power with a variable exponent): exp(exp(x))
#: is still a number a double holds for |x| < 6; exp(exp(exp(x))) overflows at x = 2.
MAX_EXP_NESTING = 2
MAX_DIGITS = 30
# Every number must survive conversion to float64, because the simulator evaluates in floats.
MAX_MAGNITUDE = sys.float_info.max

FUNCTIONS: Mapping[str, Callable] = MappingProxyType(
    {
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
)
_ARITY = {"atan2": 2}
CONSTANTS: Mapping[str, sp.Expr] = MappingProxyType({"pi": sp.pi})

_ALLOWED_CHARS = frozenset(string.ascii_letters + string.digits + "_+-*/()., \t\r\n")
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_TO_SPACE = str.maketrans("\t\r\n", "   ")
_ARITHMETIC = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}
# Friendly words for the syntax the character filter still lets through (and, defensively, some
# it does not), so an error says what the user wrote rather than an AST class name.
_REFUSALS: dict[type, str] = {
    ast.FloorDiv: "'//' is not allowed; write /",
    ast.BitXor: "'^' is not allowed; write powers as **",
    ast.Attribute: "attribute access is not allowed",
    ast.Tuple: "a comma may only separate a function's arguments",
    ast.Starred: "'*' needs a term before it",
    ast.Lambda: "lambda is not allowed",
    ast.Subscript: "subscripts are not allowed",
    ast.Compare: "comparisons are not allowed",
    ast.BoolOp: "'and'/'or' are not allowed",
    ast.IfExp: "'if'/'else' are not allowed",
    ast.GeneratorExp: "generator expressions are not allowed",
}


class ExprError(ValueError):
    """An expression outside the plain-text convention; the field and offset let the UI point."""

    def __init__(self, message: str, *, field: str = "", position: int | None = None) -> None:
        self.field, self.message, self.position = field, message, position
        super().__init__(f"{field}: {message}" if field else message)


def _number(value: object, field: str, position: int | None = None) -> sp.Expr:
    """Exact where a person would mean exact (see the module docstring), capped in size."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        kind = "true/false" if isinstance(value, bool) else f"{type(value).__name__} literals"
        raise ExprError(f"{kind} are not allowed", field=field, position=position)
    if isinstance(value, int):
        if abs(value) >= 10**MAX_DIGITS:
            raise ExprError(
                f"integer longer than {MAX_DIGITS} digits", field=field, position=position
            )
        return sp.Integer(value)
    if not math.isfinite(value):
        raise ExprError("not a finite number", field=field, position=position)
    if value.is_integer() and abs(value) < 1e15:
        return sp.Integer(int(value))
    decimal = Decimal(repr(value))
    # Only what an integer literal could also write exactly: 1e300 as an exact 10**300 makes
    # sympy's trig reductions raise TypeError/AttributeError instead of ExprError.
    if len(decimal.normalize().as_tuple().digits) <= 6 and 1e-6 <= abs(value) < 10.0**MAX_DIGITS:
        exact = Fraction(decimal)
        return sp.Rational(exact.numerator, exact.denominator)
    return sp.Float(repr(value), 15)


#: The most significant digits an exactly read decimal may have (`parse`'s ``exact_decimals``).
MAX_EXACT_DIGITS = 100


def _exact_number(literal: str, value: object, field: str, position: int | None) -> sp.Expr:
    """A decimal literal as the exact Rational of its text (``1.9999999999`` is
    19999999999/10¹⁰, ``1e-40`` is 10⁻⁴⁰), for a reader that judges what was typed: a 15-digit
    Float rounds 1/2 + 10⁻⁴⁰ to 1/2 and makes a near miss an exact hit. The usual checks first
    (finite as a double); past MAX_EXACT_DIGITS significant digits, or an exponent past a
    double's range, the usual reading."""
    number = _number(value, field, position)  # refuses what every reading refuses
    try:
        decimal = Decimal(literal.replace("_", ""))
    except ArithmeticError:
        return number
    digits = decimal.normalize().as_tuple()
    if len(digits.digits) > MAX_EXACT_DIGITS or not -1000 <= decimal.adjusted() <= 308:
        return number
    if decimal == decimal.to_integral_value() and abs(decimal) >= 10**MAX_DIGITS:
        return number  # 1e300 as an exact 10**300: what an integer literal may not write either
    exact = Fraction(decimal)
    return sp.Rational(exact.numerator, exact.denominator)


def _magnitude(value: sp.Expr) -> float:
    """|value| of a closed-form number (complex ones too); inf when it is not a finite float."""
    try:
        size = abs(complex(value.evalf(15)))
    except (TypeError, ValueError, OverflowError, ArithmeticError):
        return math.inf
    return size if math.isfinite(size) else math.inf


def _real(value: sp.Expr) -> bool:
    """Is a closed-form number real? Decided numerically: sympy's assumptions can be slow."""
    if value.is_Rational or value.is_Float:
        return True
    try:
        z = complex(value.evalf(15))
    except (TypeError, ValueError, OverflowError, ArithmeticError):
        return False
    return abs(z.imag) <= 1e-12 * max(1.0, abs(z.real))


def _precheck(text: object, field: str, max_length: int = MAX_LENGTH) -> tuple[str, int]:
    """Cheap linear scans that refuse hostile text before Python's parser or sympy see it.

    Returns the stripped text (tabs/newlines as spaces, so AST columns are character offsets)
    and how far it starts into the original, so positions always index what the user typed.
    """
    if not isinstance(text, str):
        raise ExprError(f"expected text or a number, not {type(text).__name__}", field=field)
    if len(text) > max_length:
        raise ExprError(f"longer than {max_length} characters ({len(text)})", field=field)
    for word in _WORD.finditer(text):
        if keyword.iskeyword(word.group()):
            raise ExprError(f"'{word.group()}' is not allowed", field=field, position=word.start())
        if "__" in word.group():
            raise ExprError("names with '__' are not allowed", field=field, position=word.start())
    opened: list[int] = []
    for i, ch in enumerate(text):
        if ch not in _ALLOWED_CHARS:
            if ch == "^":
                raise ExprError("'^' is not allowed; write powers as **", field=field, position=i)
            raise ExprError(f"character {ch!r} is not allowed", field=field, position=i)
        if ch == "(":
            opened.append(i)
            if len(opened) > MAX_DEPTH:
                raise ExprError(
                    f"parentheses nested deeper than {MAX_DEPTH}", field=field, position=i
                )
        elif ch == ")":
            if not opened:
                raise ExprError("')' without a matching '('", field=field, position=i)
            opened.pop()
    if opened:
        raise ExprError("'(' is never closed", field=field, position=opened[-1])
    stripped = text.strip()
    if not stripped:
        raise ExprError("empty expression", field=field)
    return stripped.translate(_TO_SPACE), len(text) - len(text.lstrip())


_GRAMMAR_TOKEN = re.compile(
    r"(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)|(?P<name>[A-Za-z_]\w*)"
    r"|(?P<op>\*\*|[-+*/])|(?P<open>\()|(?P<close>\))|(?P<comma>,)"
)


def _grammar_error(text: str) -> tuple[str, int] | None:
    """Why and where `text` is not arithmetic, for a text Python's parser refused.

    Python reports the end of the input, or column 0, for an expression that stops too early
    (``theta +``); a walk over the tokens, alternating between "a term comes next" and "an
    operator comes next", names the token that breaks the alternation instead. The position is
    where the student types the fix: just after an operator a term is missing after (``theta +``
    points past the '+'), at a token that does not belong. The message is a plain sentence (no
    "syntax error"): a student reads it. None when the walk finds nothing (Python's column is
    used then).
    """
    want_term, calls, prev = True, [], None  # calls: is each open '(' a function call's?
    pos = 0
    while True:
        while pos < len(text) and text[pos] == " ":
            pos += 1
        if pos >= len(text):
            break
        m = _GRAMMAR_TOKEN.match(text, pos)
        if m is None:
            return None
        kind, value, start = m.lastgroup, m.group(), m.start()
        pos = m.end()
        if want_term:
            if kind in ("num", "name"):
                want_term = False
            elif kind == "open":
                calls.append(False)
            elif kind == "op" and value in "+-":
                pass  # a sign
            elif kind == "close" and prev is not None and prev[0] == "open":
                if not calls or not calls[-1]:
                    return "nothing is between '(' and ')'", prev[2] + 1  # where it goes
                calls.pop()
                want_term = False
            elif kind == "op":
                return f"'{value}' needs a term before it", start
            elif prev is None:
                return f"'{value}' cannot start an expression", start
            else:
                return f"a term is missing after '{prev[1]}'", prev[2] + len(prev[1])
        elif kind == "op" or (kind == "comma" and calls and calls[-1]):
            want_term = True
        elif kind == "close":
            if not calls:
                return "')' without a matching '('", start
            calls.pop()
        elif kind == "open" and prev is not None and prev[0] == "name":
            calls.append(True)
            want_term = True
        elif kind == "open":
            return "write '*' before '(' to multiply", start
        elif kind == "comma":
            return "a comma may only separate a function's arguments", start
        else:
            return (
                f"an operator is missing before '{value}' (write '*' to multiply)",
                start,
            )
        prev = (kind, value, start)
    if want_term and prev is not None:
        return f"a term is missing after '{prev[1]}' at the end", prev[2] + len(prev[1])
    return None


def _tree(text: object, field: str, max_length: int = MAX_LENGTH) -> tuple[ast.expr, int]:
    clean, offset = _precheck(text, field, max_length)
    try:
        return ast.parse(clean, mode="eval").body, offset
    except SyntaxError as exc:
        found = _grammar_error(clean)
        if found is None:  # Python's own column, when the token walk sees nothing wrong
            message, col = "this cannot be read as arithmetic here", max((exc.offset or 1) - 1, 0)
        else:
            message, col = found
        raise ExprError(message, field=field, position=offset + col) from None
    except (RecursionError, MemoryError, ValueError):
        raise ExprError("expression too complex", field=field) from None


_EXPONENTIAL = (sp.exp, sp.sinh, sp.cosh)


@functools.lru_cache(maxsize=8192)
def _degree(expr: sp.Basic) -> float:
    """The degree that nested powers give ``expr``: a power multiplies its base's by
    |exponent| (at least 1); a sum, a product and a function keep their largest part's (a
    number is 0, a variable or derivative 1). A product of distinct factors is not counted
    together: it costs nothing to expand, unlike a power of a power of a sum. Powers of one base
    multiplied together are one power already (sympy writes x**40*x**40 as x**80)."""
    if expr.is_number:
        return 0.0
    if isinstance(expr, sp.Pow):
        base, exponent = expr.args
        if exponent.is_number:
            return _degree(base) * max(1.0, _magnitude(exponent))
        return max(_degree(base), _degree(exponent), 1.0)
    if isinstance(expr, sp.Add | sp.Mul | sp.Function) and not isinstance(expr, AppliedUndef):
        return max([1.0, *(_degree(a) for a in expr.args)])
    return 1.0  # a variable: a symbol, theta(t), a derivative of one


@functools.lru_cache(maxsize=8192)
def _exp_nesting(expr: sp.Basic) -> int:
    """How many exponentials (exp, sinh, cosh, a power with a variable exponent) nest in expr."""
    if expr.is_Atom or isinstance(expr, AppliedUndef | sp.Derivative):
        return 0
    inner = max(_exp_nesting(a) for a in expr.args)
    if isinstance(expr, _EXPONENTIAL) or (isinstance(expr, sp.Pow) and not expr.exp.is_number):
        return inner + 1
    return inner


class _Builder:
    """Turns a checked syntax tree into sympy, bottom-up, refusing anything off the whitelist."""

    def __init__(
        self,
        names: Mapping[str, sp.Expr],
        field: str,
        offset: int,
        smooth: bool = False,
        source: str | None = None,
    ) -> None:
        self.names, self.field, self.offset, self.smooth = names, field, offset, smooth
        self.source = source  # the text parsed, when decimals are read exactly from it

    def error(self, message: str, node: ast.AST | None = None) -> ExprError:
        col = getattr(node, "col_offset", None)
        return ExprError(
            message, field=self.field, position=None if col is None else col + self.offset
        )

    def build(self, node: ast.AST, depth: int = 0) -> sp.Expr:
        if depth > MAX_DEPTH:
            raise self.error(f"nested deeper than {MAX_DEPTH} levels", node)
        if isinstance(node, ast.BinOp) and type(node.op) in _ARITHMETIC:
            return self.chain(node, depth)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            value = self.build(node.operand, depth + 1)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.Constant):
            if isinstance(node.value, complex):
                raise self.error("complex numbers are not allowed", node)
            if node.value is Ellipsis:
                raise self.error("'...' is not allowed", node)
            if self.source is not None and isinstance(node.value, float):
                literal = ast.get_source_segment(self.source, node) or repr(node.value)
                return _exact_number(literal, node.value, self.field, self.at(node))
            return _number(node.value, self.field, self.at(node))
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.Call):
            return self.call(node, depth)
        if isinstance(node, ast.Tuple):
            raise self.tuple_error(node)
        refusal = _REFUSALS.get(type(getattr(node, "op", None))) or _REFUSALS.get(type(node))
        raise self.error(refusal or f"{type(node).__name__} is not allowed", node)

    def tuple_error(self, node: ast.Tuple) -> ExprError:
        """``()`` is an empty pair of parentheses; ``m, l`` has a comma, pointed at."""
        if not node.elts:
            return ExprError(
                "nothing is between '(' and ')'",
                field=self.field,
                position=self.at(node) + 1,  # where the missing term goes
            )
        first = node.elts[0]
        after = getattr(first, "end_col_offset", None)
        position = None if after is None else after + self.offset
        return ExprError(_REFUSALS[ast.Tuple], field=self.field, position=position)

    def at(self, node: ast.AST) -> int:
        return node.col_offset + self.offset

    def chain(self, node: ast.BinOp, depth: int) -> sp.Expr:
        # a+b+c+... leans left in the AST; walking that spine in a loop keeps a long sum of terms
        # (an equation of motion) from counting as deep nesting or exhausting Python's stack, and
        # handing each run of + - (or * /) to one Add (Mul) keeps it linear rather than quadratic.
        spine = []
        while isinstance(node, ast.BinOp) and type(node.op) in _ARITHMETIC:
            spine.append(node)
            node = node.left
        value = self.build(node, depth + 1)
        run: list[sp.Expr] = []
        combine: Callable = sp.Add
        last: ast.AST = node
        for op_node in reversed(spine):
            op = type(op_node.op)
            right = self.build(op_node.right, depth + 1)
            if op is ast.Pow:
                value = self.finite(combine(value, *run), last) if run else value
                run = []
                self.check_power(value, right, op_node.right)  # point at the exponent
                value = self.bounded(self.finite(value**right, op_node), op_node.right)
                continue
            kind = sp.Add if op in (ast.Add, ast.Sub) else sp.Mul
            if run and kind is not combine:
                value, run = self.finite(combine(value, *run), last), []
            if op is ast.Div and right == 0:
                raise self.error("division by zero", op_node)
            combine, last = kind, op_node
            run.append(-right if op is ast.Sub else 1 / right if op is ast.Div else right)
        if not run:
            return value
        # past the limit at the last operand of the run: the factor that took it over
        return self.bounded(self.finite(combine(value, *run), last), getattr(last, "right", last))

    def check_power(self, base: sp.Expr, exponent: sp.Expr, node: ast.AST) -> None:
        """Refuse powers before sympy computes them: 9**387420489 would take minutes and memory."""
        if not exponent.is_number:
            return
        size = _magnitude(exponent)
        if size > MAX_EXPONENT:
            raise self.error(f"exponent too large (the limit is {MAX_EXPONENT})", node)
        if base.is_number and base != 0:
            if size * abs(math.log10(_magnitude(base) or 1.0)) > 300:
                raise self.error("number too large or too small", node)

    def finite(self, value: sp.Expr, node: ast.AST) -> sp.Expr:
        # Only numbers can overflow or become zoo/nan (x/0 is refused separately), and a run's
        # numbers collect in the top Add/Mul's arguments (the 10**600 of 1e300*1e300*x).
        # `is_number` stops at a term's first symbol, so this stays cheap on long sums.
        if value.is_number:
            parts: tuple = (value,)
        else:
            parts = value.args if isinstance(value, sp.Add | sp.Mul) else ()
        for part in parts:
            if part.is_number and _magnitude(part) > MAX_MAGNITUDE:
                raise self.error("not a finite number", node)
            if part.is_number and not _real(part):
                # acos(65) is complex: meaningless in mechanics, and sympy can spend minutes
                # on expressions built from such constants (atan2(acos(65), 0)).
                raise self.error("not a real number", node)
        return value

    def bounded(self, value: sp.Expr, node: ast.AST) -> sp.Expr:
        """Refuse an expression whose degree or nesting of exponentials is past the limits: a
        power of a power, or powers multiplied, can reach x**4096 with every exponent ≤ 64,
        and sympy then spends minutes on it, or every double overflows."""
        degree = _degree(value)
        if degree > MAX_DEGREE:
            raise self.error(
                f"the powers here reach degree {degree:g}, over the limit of {MAX_DEGREE}: a "
                "power of a power multiplies the exponents ((x**8)**8 is x**64), powers of one "
                "base multiplied add them (x**40*x**40 is x**80)",
                node,
            )
        if _exp_nesting(value) > MAX_EXP_NESTING:
            raise self.error(
                f"exponentials nested more than {MAX_EXP_NESTING} deep (exp of exp of exp, or "
                "a power with a variable exponent inside one): no double can hold their values",
                node,
            )
        return value

    def name(self, node: ast.Name) -> sp.Expr:
        if node.id in self.names:
            return self.names[node.id]
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        if node.id in FUNCTIONS:
            raise self.error(f"function '{node.id}' needs arguments in parentheses", node)
        message = f"unknown name '{node.id}'"
        close = difflib.get_close_matches(node.id, list(self.names), n=1)
        if close:
            message += f"; did you mean '{close[0]}'?"
        known = sorted(self.names)
        if known:
            more = ", ..." if len(known) > 12 else ""
            message += f" (known: {', '.join(known[:12])}{more})"
        raise self.error(message, node)

    def call(self, node: ast.Call, depth: int) -> sp.Expr:
        if not isinstance(node.func, ast.Name):
            raise self.error("only the listed functions may be called, by name", node)
        name = node.func.id
        if name not in FUNCTIONS:
            if name in self.names or name in CONSTANTS:
                after = getattr(node.func, "end_col_offset", None)  # where the '*' goes
                raise ExprError(
                    f"'{name}' is a name, not a function: write '*' before '(' to multiply",
                    field=self.field,
                    position=None if after is None else after + self.offset,
                )
            raise self.error(
                f"function '{name}' is not allowed (allowed: {', '.join(FUNCTIONS)})", node
            )
        for keyword_ in node.keywords:
            if keyword_.arg is None:  # sin(**x): a power with nothing before it, to a student
                raise ExprError(
                    "'**' needs a term before it",
                    field=self.field,
                    position=getattr(keyword_, "col_offset", node.col_offset) + self.offset,
                )
        if node.keywords:
            raise self.error(f"{name}() takes no keyword arguments", node)
        for arg in node.args:
            if isinstance(arg, ast.Starred):
                raise self.error(_REFUSALS[ast.Starred], arg)
        arity = _ARITY.get(name, 1)
        if len(node.args) != arity:
            plural = "s" if arity > 1 else ""
            raise self.error(f"{name}() takes {arity} argument{plural}, not {len(node.args)}", node)
        args = [self.build(arg, depth + 1) for arg in node.args]
        if self.smooth and name in _KINKED and any(a.has(AppliedUndef) for a in args):
            raise self.error(
                f"{name}() of a coordinate has no derivative where its argument is 0, and this "
                "expression is differentiated in time (a position or an angle): write it for "
                "the side the motion stays on",
                node,
            )
        if name == "atan2" and any(a.is_number and a.is_extended_real is False for a in args):
            # sympy's atan2(acos(65), 0) grinds for minutes deciding the sign of i*acosh(65).
            raise self.error("atan2() takes real arguments", node)
        return self.bounded(self.finite(FUNCTIONS[name](*args), node), node)


#: Functions with a kink or a jump: a force may hold them (friction's sign(ṡ)), an expression
#: that is differentiated in time may not hold them of a coordinate (see `parse`'s smooth).
_KINKED = frozenset({"abs", "sign"})


def parse(
    text: str | int | float,
    names: Mapping[str, sp.Expr],
    *,
    field: str = "",
    smooth: bool = False,
    max_length: int = MAX_LENGTH,
    exact_decimals: bool = False,
) -> sp.Expr:
    """The only way user text becomes sympy: every node is checked against the whitelist.

    ``smooth``: the expression is differentiated in time (a position, a frame's angle), so
    abs() and sign() of a coordinate are refused: their derivatives stay unevaluated in sympy
    and no later step can put numbers into them. ``max_length``: for a text a caller rewrote
    from one it bounded itself (a student's answer, spaced out between its tokens).
    ``exact_decimals``: every decimal literal is the exact Rational of its text (the answer
    checker's reading: a number is judged as typed), not the module docstring's rule."""
    if isinstance(text, int | float) and not isinstance(text, bool):
        return _number(text, field)
    tree, offset = _tree(text, field, max_length)
    source = text.strip().translate(_TO_SPACE) if exact_decimals else None
    result = _Builder(names, field, offset, smooth, source).build(tree)
    if result.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise ExprError("not a finite number", field=field)
    return result


def free_names(text: str, *, field: str = "") -> set[str]:
    """The identifiers a text uses, so callers can report every unknown name at once."""
    tree, _ = _tree(text, field)
    used = {node.id for node in ast.walk(tree) if isinstance(node, ast.Name)}
    return used - set(FUNCTIONS) - set(CONSTANTS)


class _PlainPrinter(StrPrinter):
    """sympy's str printer, made to speak the input convention so its output parses back."""

    def _print_Function(self, expr: sp.Expr) -> str:
        # theta(t) is what the user calls theta.
        if isinstance(expr, AppliedUndef) and len(expr.args) == 1 and expr.args[0].is_Symbol:
            return expr.func.__name__
        return super()._print_Function(expr)

    def _print_Abs(self, expr: sp.Expr) -> str:
        return f"abs({self._print(expr.args[0])})"

    def _print_Derivative(self, expr: sp.Derivative) -> str:
        base = expr.expr
        order = sum(count for _, count in expr.variable_count)
        if (
            isinstance(base, AppliedUndef)
            and len(base.args) == 1
            and all(var == base.args[0] for var, _ in expr.variable_count)
            and order in (1, 2)
        ):
            return f"{base.func.__name__}_{'d' * (order - 1)}dot"
        return super()._print_Derivative(expr)

    def _print_Float(self, expr: sp.Float) -> str:
        text = format(float(expr), ".15g")
        return text if any(c in text for c in ".ein") else text + ".0"

    def _print_Exp1(self, expr: sp.Expr) -> str:
        return "exp(1)"

    def _print_ImaginaryUnit(self, expr: sp.Expr) -> str:
        return "sqrt(-1)"


_PLAIN = _PlainPrinter({"order": None})


def to_plain(expr: sp.Expr | list) -> str:
    """Plain text in the input convention, so a result can be pasted back into an input field."""
    if isinstance(expr, list):
        return "[" + ", ".join(to_plain(e) for e in expr) + "]"
    if isinstance(expr, sp.Basic):
        return _plain_memo(expr)  # a derivation prints each quantity in its step and its summary
    return _PLAIN.doprint(expr)


@functools.lru_cache(maxsize=4096)
def _plain_memo(expr: sp.Basic) -> str:
    return _PLAIN.doprint(expr)


def to_latex(expr: sp.Expr) -> str:
    """Textbook LaTeX: dots for time derivatives, Greek names as letters, digits as subscripts.

    vlatex (not sympy.latex) because it drops the (t) of coordinates and draws q' as a dot;
    it accepts physics.vector Vectors and matrices too. Inverse trig functions print as the
    notes write them (\\arccos, not \\operatorname{acos}).
    """
    if isinstance(expr, sp.Expr):
        return _latex_memo(expr)
    return vlatex(expr, inv_trig_style="full")


@functools.lru_cache(maxsize=4096)
def _latex_memo(expr: sp.Expr) -> str:
    return vlatex(expr, inv_trig_style="full")
