"""Student answers as typed (`m l^2 theta'^2/2`, `thetadot`, `θ̇`) -> the strict plain convention.

The rewriting works on tokens, never on evaluated text: Greek letters and primes become names,
`^` becomes `**`, juxtaposition becomes `*`, and a run of letters that is no known name is split
into known names when exactly one way exists (`mgl` -> `m*g*l`). The result then goes through the
same whitelist parser as every other expression, which reports what is still wrong, and where.

`read_answer` is the one way a check or a prediction reads an answer: the rewrite, the parse, an
equation's two sides, and every error's position carried back to the character the student typed.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable

import sympy as sp

from mechanics.derive import Derivation
from mechanics.expr import FUNCTIONS, MAX_EXP_NESTING, MAX_LENGTH, ExprError, parse
from mechanics.model import T

GREEK = {
    "θ": "theta", "ϑ": "theta", "φ": "phi", "ϕ": "phi", "ψ": "psi", "ω": "omega", "Ω": "Omega",
    "α": "alpha", "β": "beta", "γ": "gamma", "δ": "delta", "μ": "mu", "ρ": "rho", "τ": "tau",
    "π": "pi", "η": "eta", "ξ": "xi", "ζ": "zeta", "κ": "kappa", "σ": "sigma", "ν": "nu",
}  # fmt: skip
SYMBOLS = {"·": "*", "×": "*", "−": "-", "²": "^2", "³": "^3", "½": "(1/2)", "⋅": "*"}
DOT, DDOT = "\u0307", "\u0308"  # combining dot above / diaeresis: θ̇, θ̈

_TOKEN = re.compile(
    r"(?P<num>\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<prime>'+)"
    r"|(?P<mark>[\u0307\u0308])"
    r"|(?P<op>\*\*|\^|[-+*/(),=])"
    r"|(?P<space>\s+)"
)


def _normalise(text: str) -> tuple[str, list[int]]:
    """Greek letters and math symbols as plain names and operators, and for each character of
    the result the index of the typed character it came from (errors point at what was typed)."""
    out: list[str] = []
    origin: list[int] = []
    for i, ch in enumerate(text):
        # a lone d before a Greek letter is a differential (dθ/dt): dtheta, not d*theta
        differential = i and text[i - 1] == "d" and (i < 2 or not text[i - 2].isalnum())
        piece = (("" if differential else " ") + GREEK[ch]) if ch in GREEK else SYMBOLS.get(ch, ch)
        out.append(piece)
        origin += [i] * len(piece)
    return "".join(out), origin


def _velocity_name(name: str, coordinates: set[str], known: set[str]) -> str | None:
    """thetadot/theta_dot/dtheta -> theta_dot; thetaddot/ddtheta -> theta_ddot."""
    for suffix, canon in (("_ddot", "_ddot"), ("ddot", "_ddot"), ("_dot", "_dot"), ("dot", "_dot")):
        if name.endswith(suffix) and name[: -len(suffix)] in coordinates:
            return name[: -len(suffix)] + canon
    for prefix, canon in (("dd", "_ddot"), ("d", "_dot")):
        base = name[len(prefix) :]
        if name.startswith(prefix) and base in coordinates and name not in known:
            if "d" in known:
                raise ExprError(
                    f"'{name}' is ambiguous here (d*{base} or {base}_dot); write {base}_dot "
                    f"or d*{base}"
                )
            return base + canon
    return None


def _split(name: str, vocabulary: set[str]) -> list[str] | None:
    """The one way to write `name` as a run of known names, or None (none, or ambiguous)."""
    ways: list[list[list[str]]] = [[] for _ in range(len(name) + 1)]
    ways[0] = [[]]
    for end in range(1, len(name) + 1):
        for start in range(max(0, end - 24), end):
            piece = name[start:end]
            if piece in vocabulary and ways[start]:
                ways[end] += [w + [piece] for w in ways[start]][:2]
        ways[end] = ways[end][:2]
    return ways[-1][0] if len(ways[-1]) == 1 else None


def to_convention(
    text: str, coordinates: Iterable[str], known: Iterable[str], *, field: str = "answer"
) -> str:
    """Rewrite a student's text into the strict convention; ExprError says where it cannot."""
    return to_convention_mapped(text, coordinates, known, field=field)[0]


def to_convention_mapped(
    text: str, coordinates: Iterable[str], known: Iterable[str], *, field: str = "answer"
) -> tuple[str, list[int]]:
    """`to_convention`, and for each character of the result the index of the typed character
    it came from (the end of the text for inserted ones), so the parser's positions can be
    carried back to what the student typed."""
    if not isinstance(text, str):
        raise ExprError("expected text", field=field)
    if len(text) > MAX_LENGTH:
        raise ExprError(f"answer longer than {MAX_LENGTH} characters", field=field)
    coordinates = list(coordinates)
    example = coordinates[0] if coordinates else "x"  # what a refusal writes as the argument
    coordinates, known = set(coordinates), set(known)
    vocabulary = known | set(FUNCTIONS) | {"pi"}
    typed = text
    text, origin = _normalise(text)
    origin.append(len(typed))
    out: list[tuple[str, str, int]] = []  # (kind, text, where it was typed)
    power = None  # sin^2 seen: (its exponent, where), waiting for the argument
    function = ""  # the function name of that sin^2, for the refusal to name it
    closes: list[tuple[int, str, int]] = []  # (depth, exponent, where): sin^2( ... ) ** 2
    # `cos θ` just read with no parentheses: (cos, or cos^2, and where θ is in out). What may
    # follow decides if the text reads one way only. A power never does (`cos θ^3`: cos³θ or
    # cos(θ³)?); a factor does after a coordinate (`sin θ φ'`, `cos θ (1 - cos θ)`: a product,
    # as the notes write sin²θ φ̇²), not after a number or a parameter (`sin 2 θ`, `cos w t`:
    # cos(w t) to the student, cos(w)·t to a parser), nor `*` after them (`cos 2*θ` alike)
    bare: tuple[str, int] | None = None
    depth = 0
    pos = 0

    def power_refused(at: int) -> ExprError:
        return ExprError(_function_power(function, example), field=field, position=at)

    def argument_refused(after: str, at: int) -> ExprError:
        fn, atom = bare[0], out[bare[1]][1]
        return ExprError(_ambiguous_argument(fn, atom, after), field=field, position=at)

    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m:
            raise ExprError(
                f"character {text[pos]!r} is not allowed", field=field, position=origin[pos]
            )
        pos = m.end()
        kind = m.lastgroup
        value = m.group(kind)
        if kind == "space":
            continue
        if kind in ("prime", "mark"):
            order = len(value) if kind == "prime" else (1 if value == DOT else 2)
            # cos θ' is cos(θ'): the prime belongs to the argument just wrapped
            k = bare[1] if bare and out[-1][1] == ")" else len(out) - 1
            if not out or out[k][0] != "name" or out[k][1] not in coordinates:
                if out and out[k][0] == "name":  # a rate of something: name what it is instead
                    message = _not_a_coordinate(out[k][1], coordinates, known)
                    raise ExprError(message, field=field, position=out[k][2])
                raise ExprError(
                    "a prime or dot must follow a coordinate name",
                    field=field,
                    position=origin[m.start()],
                )
            out[k] = ("name", out[k][1] + ("_dot" if order == 1 else "_ddot"), out[k][2])
            continue
        if kind == "op" and value == "^":
            value = "**"
        at = origin[m.start()]
        if bare is not None:  # cos θ, then: an operator is unambiguous, a power or a factor not
            if kind == "op" and value == "**":
                raise argument_refused("^" + _next_token(text, pos), at)
            product = out[bare[1]][1] in coordinates
            if kind == "num" or (value == "(" and not product):
                raise argument_refused("(...)" if value == "(" else value, at)
            if kind == "op" and value == "*" and not product:  # cos 2*θ: cos(2θ) or cos(2)·θ?
                after = _next_token(text, pos)
                raise argument_refused("*" + ("(...)" if after == "n" else after), at)
            if kind == "op":
                bare = None
        if power == "":  # sin^ was the last thing: a whole number must come
            if kind != "num" or not value.isdigit():
                raise power_refused(at)
            power = (value, at)
            continue
        if kind == "op" and value == "**" and out and out[-1][0] == "name":
            if out[-1][1] in FUNCTIONS:  # sin^2(θ), sin^2 θ: the notes' sin²θ is sin(θ)^2
                function = out[-1][1]
                if power is not None:  # sin^2^2: no argument yet, a second power
                    raise power_refused(at)
                power = ""
                # (sin θ ** 2) is one operand: sin^2(θ)^3 is (sin²θ)³, not sin θ ** (2 ** 3)
                out.insert(len(out) - 1, ("op", "(", out[-1][2]))
                continue
        if power is not None:
            if value == "(":
                closes.append((depth, *power))
            elif kind not in ("num", "name"):
                raise power_refused(at)
        if kind == "name" and _is_time_derivative(out, value, typed, known):
            rest = text[m.end() :]
            if rest.lstrip()[:1] != "(":  # point where the '(' goes: before what d/dt is of
                where_open = m.end() + len(rest) - len(rest.lstrip())
                raise ExprError(_DDT_PARENTHESES, field=field, position=origin[where_open])
            out.pop()
            at = out.pop()[2]
            _append(out, "name", DDT, at)
            continue
        if kind == "name" and value == "dt" and "dt" not in known and _leibniz(out, typed):
            out.pop()  # dtheta/dt: the '/' goes, dtheta already reads theta_dot
            continue
        if kind == "name":
            try:
                pieces = _resolve(value, coordinates, known, vocabulary)
            except ExprError as exc:
                raise ExprError(exc.message, field=field, position=origin[m.start()]) from None
            for k, piece in enumerate(pieces):
                if bare is not None:
                    if piece not in FUNCTIONS and out[bare[1]][1] not in coordinates:
                        raise argument_refused(piece, at)  # cos w t: cos(w) t or cos(w t)?
                    bare = None  # sin θ cos θ, sin θ φ'
                wraps = _wraps(out, kind)
                _append(out, "name", piece, at)
                if wraps:
                    bare = (out[-4][1], len(out) - 2)
                if k == 0 and power is not None and power != "":  # sin^2 θ: (sin(θ) ** 2)
                    bare = (f"{function}^{power[0]}", len(out) - 2)
                    out += _power(*power)
                    power = None
            continue
        wraps = _wraps(out, kind)
        _append(out, kind, value, at)
        if wraps:
            bare = (out[-4][1], len(out) - 2)
        if kind == "num" and power is not None:  # sin^2 3: the one atom taken
            bare = (f"{function}^{power[0]}", len(out) - 2)
            out += _power(*power)
            power = None
        elif value == "(":
            depth += 1
            if power is not None:
                power = None  # its closing ')' carries the power (closes)
        elif value == ")":
            depth -= 1
            if closes and closes[-1][0] == depth:
                _, exponent, where_typed = closes.pop()
                out += _power(exponent, where_typed)
    if power is not None:
        raise power_refused(len(typed))
    result: list[str] = []
    where: list[int] = []
    for k, (_, value, at) in enumerate(out):
        if k:
            result.append(" ")
            where.append(at)  # the space before a token points at the token
        result.append(value)
        where += [at] * len(value)
    where.append(len(typed))
    return "".join(result), where


def _not_a_coordinate(name: str, coordinates: set[str], known: set[str]) -> str:
    """Why `name'` is refused, about the name the student typed: a misspelt coordinate gets
    the parser's did-you-mean (`thetta1'` -> theta1), a name of another scene (`theta'` where
    the only coordinate is x) the coordinates this scene has, a parameter that it is one."""
    listed = ", ".join(sorted(coordinates))
    if name in known or name in FUNCTIONS or name == "pi":
        what = "the time" if name == "t" else "not a coordinate"
        return (
            f"a prime or dot must follow a coordinate name: '{name}' is {what}; the "
            f"coordinates of this scene are {listed}"
        )
    close = difflib.get_close_matches(name, sorted(coordinates), n=1)
    if close:
        return f"unknown name '{name}'; did you mean '{close[0]}'?"
    return f"'{name}' is not a coordinate of this scene; its coordinates are {listed}"


def _function_power(function: str, argument: str) -> str:
    """The refusal of a power after a function name the reader cannot take, naming the function
    the student typed (cos^-1 θ is about cos, not sin)."""
    inverse = f"the inverse is a{function}(...), " if f"a{function}" in FUNCTIONS else ""
    return (
        f"write {function}^2({argument}) (or {function}({argument})^2) for the square of "
        f"{function}({argument}): after {function}^ comes a whole number, then the argument; "
        f"{inverse}the reciprocal 1/{function}(...)"
    )


def _ambiguous_argument(function: str, argument: str, after: str) -> str:
    """The refusal of a function without parentheses followed by a power or a factor: `cos θ^3`
    is cos³θ to some and cos(θ³) to others, `sin 2 θ` is sin(2θ) or sin(2)·θ. Either reading
    would judge some student wrongly, so the student says which."""
    if after.startswith("^"):
        one, other = f"{function}({argument}){after}", f"{function}({argument}{after})"
    elif after.startswith("*"):
        one, other = f"{function}({argument}{after})", f"{function}({argument}){after}"
    else:
        one, other = f"{function}({argument} {after})", f"{function}({argument}) {after}"
    return (
        f"'{function} {argument}' followed by '{after}' can be read two ways: put the "
        f"argument of {function.split('^')[0]} in parentheses, {one} or {other}"
    )


def _next_token(text: str, pos: int) -> str:
    """The token after `pos` (an exponent, to quote it back), or 'n' when it is no atom."""
    m = _TOKEN.match(text, pos)
    while m and m.lastgroup == "space":
        m = _TOKEN.match(text, m.end())
    return m.group() if m and m.lastgroup in ("num", "name") else "n"


def _power(exponent: str, at: int) -> list[tuple[str, str, int]]:
    """`** n )`: closes the '(' put before the function name, so sin^2 θ is one operand."""
    return [("op", "**", at), ("num", exponent, at), ("op", ")", at)]


def _wraps(out: list[tuple[str, str, int]], kind: str) -> bool:
    """Will `_append` read this atom as the argument of the function just before it?"""
    return (
        kind in ("num", "name")
        and bool(out)
        and out[-1][:1] == ("name",)
        and (out[-1][1] in FUNCTIONS)
    )


_DDT_PARENTHESES = (
    "d/dt needs its expression in parentheses: d/dt(m l^2 theta'), or write the derivative "
    "out with theta' and theta''"
)
#: The token a typed `d/dt(` becomes: read_answer differentiates what its parentheses hold.
DDT = "d_dt"
#: Past this size (count_ops) the expression under d/dt is not differentiated: the product rule
#: on a long product is quadratic in its length.
MAX_DDT_OPS = 200
#: At most this many d/dt(...) in one answer (each is a parse and a derivative).
MAX_DDT = 8


def _is_time_derivative(out: list[tuple[str, str, int]], value: str, typed: str, known) -> bool:
    """Is the text so far `d /` and this name `dt`: the operator d/dt (typed as such, a lone
    d, even where d is a length: d/dt is never d divided by d t)?"""
    if value != "dt" or "dt" in known or DDT in known or len(out) < 2:
        return False
    if out[-1][:2] != ("op", "/") or out[-2][:2] != ("name", "d"):
        return False
    at = out[-2][2]
    return typed[at : at + 1] == "d" and (at == 0 or not typed[at - 1].isalnum())


def _leibniz(out: list[tuple[str, str, int]], typed: str) -> bool:
    """Is the text so far `d<q> /`, a derivative dq/dt in Leibniz's notation (what a student
    types for q̇: `1/2 m l^2 (dtheta/dt)^2`)?"""
    if len(out) < 2 or out[-1][:2] != ("op", "/"):
        return False
    kind, name, at = out[-2]
    return kind == "name" and name.endswith("_dot") and typed[at : at + 1] == "d"


def _resolve(name: str, coordinates: set[str], known: set[str], vocabulary: set[str]) -> list[str]:
    if name in known or name in FUNCTIONS or name == "pi":
        return [name]
    velocity = _velocity_name(name, coordinates, known)
    if velocity:
        return [velocity]
    pieces = _split(name, vocabulary | {f"{q}dot" for q in coordinates})
    if pieces:
        return [_velocity_name(p, coordinates, known) or p for p in pieces]
    return [name]  # the parser reports it as unknown, naming it


def _append(out: list[tuple[str, str, int]], kind: str, value: str, at: int) -> None:
    """Insert the '*' that juxtaposition means (`2 m`, `m l`, `l (`, `) (`), not before calls.

    A function written without parentheses takes the one atom after it: `cos θ` -> cos(theta).
    """
    if _wraps(out, kind):
        out += [("op", "(", at), (kind, value, at), ("op", ")", at)]
        return
    if out:
        prev_kind, prev, _ = out[-1]
        left = (
            prev_kind == "num"
            or prev == ")"
            or (prev_kind == "name" and prev not in FUNCTIONS and prev != DDT)
        )
        right = kind in ("num", "name") or value == "("
        if left and right:
            out.append(("op", "*", at))
    out.append((kind, value, at))


def answer_names(d: Derivation) -> dict[str, sp.Expr]:
    """The names an answer may use: the scene's, t, and q̈ of every coordinate."""
    model = d.model
    names = dict(model.names)
    names.update(
        {f"{q}_ddot": qdd for q, qdd in zip(model.coordinate_names, model.qdd, strict=True)}
    )
    return names


def read_answer(
    d: Derivation, quantity: str, answer: str, j: int | None, *, exact_decimals: bool = False
) -> tuple[sp.Expr, sp.Expr]:
    """The answer as one expression, and the part of it typed right of '=' (zero without one).

    An equation of motion may be written `lhs = rhs` (read as lhs − rhs = 0); q̈ may be written
    `theta_ddot = ...`. Every ExprError points at the character the student typed, not at the
    rewritten text the parser saw. ``exact_decimals``: each decimal is the exact value of its
    text (the checker judges numbers as typed: 1.9999999999 is not 2).
    """
    model = d.model
    try:
        text, where = to_convention_mapped(
            answer, model.coordinate_names, model.names.keys() | {"t"}
        )
    except ExprError as exc:  # the notation rewrite's positions already count what was typed
        raise _pointed(exc.message, answer, exc.position) from None
    names = answer_names(d)

    def read(start: int, end: int) -> sp.Expr:
        try:
            # the typed answer is at most MAX_LENGTH characters, so at most that many tokens;
            # its rewrite spaces them out and spells them (θ -> theta, θθ -> theta * theta)
            return parse(
                text[start:end],
                names,
                field="answer",
                max_length=10 * MAX_LENGTH,
                exact_decimals=exact_decimals,
            )
        except ExprError as exc:
            at = None if exc.position is None else where[min(start + exc.position, len(text))]
            message = exc.message
            located = exc.position is not None
            nest = _exponential_nest(text, start + exc.position) if located else None
            if (
                nest is not None
                and nest[1] > MAX_EXP_NESTING  # else powers with variable exponents count too
                and message.startswith("exponentials nested more than")
            ):
                # the parser stops at the first sub-expression past the limit (exp(exp(exp(…
                # inside exp(…)): point at the whole nest the student typed, and count it
                at, depth = where[nest[0]], nest[1]
                message = (
                    f"{depth} exponentials nested one inside another from here (exp, sinh, "
                    f"cosh); at most {MAX_EXP_NESTING} may nest: exp(exp(exp(x))) is already "
                    "past what a double can hold at x = 3"
                )
            elif exc.position is not None and "'**'" in message:
                # the parser saw '**' where the student typed '^': name what was typed
                k = start + exc.position
                ops = [i for i in (k, k - 2) if 0 <= i and text[i : i + 2] == "**"]
                if ops and answer[where[ops[0]]] == "^":
                    message = message.replace("'**'", "'^'")
            raise _pointed(message, answer, at) from None

    text, names = _time_derivatives(text, where, names, read, answer, model)
    if "=" not in text:
        return read(0, len(text)), sp.S.Zero
    equals = text.index("=")
    double = re.search(r"=\s*=", text)  # a programmer's equality (the rewrite spaces tokens)
    if double:
        raise _pointed(
            "write one '=' between the two sides, not '=='", answer, where[double.start()]
        )
    if quantity not in ("eom", "accel"):
        raise _pointed(
            "'=' belongs only in an equation of motion or q̈ = ...: this answer is one expression",
            answer,
            where[equals],
        )
    if text.count("=") > 1:  # point at the second '=', the first one too many
        raise _pointed(
            f"an equation has one '=' between its two sides; this has {text.count('=')}",
            answer,
            where[text.index("=", equals + 1)],
        )
    lhs, rhs = read(0, equals), read(equals + 1, len(text))
    if quantity == "eom":
        return lhs - rhs, rhs
    qdd = model.qdd[j]
    if lhs == qdd or rhs == qdd:
        return (rhs if lhs == qdd else lhs), sp.S.Zero
    name = model.coordinate_names[j]
    raise _pointed(f"write q̈ as '{name}_ddot = ...'", answer, where[equals])


_EXPONENTIALS = ("exp", "sinh", "cosh")  # the functions the parser's nesting limit counts


def _exponential_nest(text: str, k: int) -> tuple[int, int] | None:
    """The outermost exponential call (exp, sinh, cosh) of the rewritten ``text`` whose span
    holds position ``k``, and how many exponential calls nest in it at most: (where its name
    starts, that depth). None when no exponential call holds ``k``."""
    stack: list[int | None] = []  # each open '(': where its exponential's name starts, or None
    depths: dict[int, int] = {}  # outermost exponential's start -> deepest nesting under it
    spans: dict[int, int] = {}  # outermost exponential's start -> where its ')' is
    previous = None
    for m in _TOKEN.finditer(text):
        kind, value = m.lastgroup, m.group()
        if kind == "space":
            continue
        if value == "(":
            exponential = previous is not None and previous.group() in _EXPONENTIALS
            stack.append(previous.start() if exponential else None)
            starts = [at for at in stack if at is not None]
            if starts:
                depths[starts[0]] = max(depths.get(starts[0], 0), len(starts))
        elif value == ")" and stack:
            at = stack.pop()
            if at is not None and all(x is None for x in stack):
                spans[at] = m.start()
        previous = m if kind == "name" else None
    for start, end in spans.items():
        if start <= k <= end:
            return start, depths[start]
    return None


def _time_derivatives(
    text: str, where: list[int], names: dict[str, sp.Expr], read, typed: str, model
) -> tuple[str, dict[str, sp.Expr]]:
    """Each `d/dt( … )` of the answer replaced by the total time derivative of what it holds
    (∂/∂q q̇ + ∂/∂q̇ q̈ + ∂/∂t: q is q(t) here, so sympy's d/dt is exactly that), bound to a
    name of the same length in the text, so every later position still points where it did.
    The expression inside is read by the same parser, and bounded before it is differentiated.
    """
    found = [m.start() for m in re.finditer(rf"\b{DDT} \(", text)]
    if not found:
        return text, names
    if len(found) > MAX_DDT:
        raise _pointed(f"at most {MAX_DDT} d/dt(...) in one answer", typed, where[found[-1]])
    names = dict(names)
    spans = []
    for start in found:
        open_at = start + len(DDT) + 1
        level, close = 0, None
        for k in range(open_at, len(text)):
            level += {"(": 1, ")": -1}.get(text[k], 0)
            if level == 0:
                close = k
                break
        if close is None:
            raise _pointed("'(' after d/dt is never closed", typed, where[open_at])
        if spans and start < spans[-1][1]:
            raise _pointed(
                "d/dt inside d/dt: write a second derivative with theta''", typed, where[start]
            )
        spans.append((start, close + 1))
    out = list(text)
    for k, (start, end) in enumerate(spans):
        inner = read(start + len(DDT) + 2, end - 1)
        if any(inner.has(a) for a in model.qdd):
            raise _pointed(
                "d/dt of an acceleration is a third derivative, which no answer here needs",
                typed,
                where[start],
            )
        if inner.has(sp.Abs, sp.sign):
            raise _pointed(
                "d/dt of abs() or sign() has no derivative where its argument is 0: write the "
                "derivative out for the side the motion stays on",
                typed,
                where[start],
            )
        derivative = sp.diff(inner, T) if sp.count_ops(inner) <= MAX_DDT_OPS else None
        if derivative is None or sp.count_ops(derivative) > 2 * MAX_DDT_OPS:
            raise _pointed(
                "the expression under d/dt is too long to differentiate here: write its "
                "derivative out",
                typed,
                where[start],
            )
        rates = {*(q.diff(T) for q in model.q), *model.qdd}
        if not derivative.atoms(sp.Derivative) <= rates:  # sympy left one unevaluated
            raise _pointed(
                "this d/dt is not one the checker can take: write its derivative out",
                typed,
                where[start],
            )
        name = f"ddt{k}_"
        while name in names:
            name += "_"
        names[name] = derivative
        out[start:end] = list(name.ljust(end - start))
    return "".join(out), names


def _pointed(message: str, typed: str, at: int | None) -> ExprError:
    """An ExprError whose message shows where, in the text as typed: `theta + ◂here`."""
    if at is None:
        return ExprError(message, field="answer")
    at = max(0, min(at, len(typed)))
    before, after = typed[max(0, at - 24) : at], typed[at : at + 24]
    shown = ("…" if at > 24 else "") + before + "⟨here⟩" + after
    shown += "…" if at + 24 < len(typed) else ""
    return ExprError(
        f"{message} (at character {at + 1}: {shown.strip()})", field="answer", position=at
    )
