"""A scene's compiled equations as a JavaScript module, so the page can integrate in the browser.

Why: a slider should move the motion while it moves (within 50 ms), and a bob dragged on the
canvas should swing from where it is dropped. A server round trip per slider event cannot do that,
and a class of 200 dragging at once would need a bigger server. The browser steps the same
equations instead (static/js/live.js, a fixed-step RK4) and the server's run stays the measured
reference, asked for when the slider is let go.

The JavaScript is printed from the very sympy expressions mechanics/numeric.py compiles for Python
and mechanics/native prints as C, in the same safe way: every symbol becomes an array slot
(``t``, ``y[i]``, ``p[k]``), common subexpressions become numbered temporaries (``x12``), and the
printed text is checked against a whitelist of identifiers (``Math.sin`` and friends, slots,
temporaries) and characters (no quotes, braces or semicolons inside an expression) before it is
served. No name the user typed (a coordinate, a parameter, a body) appears in the module: the
page learns the names, in slot order, from the JSON beside it (`live_names`).

The module exports::

    dims = {n, extras, params, points, frames}
    rhs(t, y, p, dy)       // dy/dt for y = [q, q̇, W_NC (, W_t)]; 0, or 2 where M is singular
    places(t, y, p, out)   // out[3k..3k+2] = x, y, z of point k (bodies and named points)
    axes(t, y, p, out)     // out[9f..9f+8] = the 3 axes of frame f in N (rows, as the server's)
    energy(t, y, p, out)   // out[0] = T, out[1] = V
    stops(t, y, p, out)    // out[2k] = stop k's value (> 0 while the model holds), out[2k+1]
                           // its guard (only_if; the stop applies where it is not < 0)

A stop on a string's tension needs Newton's method and is not printed: the preview does not
watch it (`LiveModule.stops` lists the ones it does, with their names and messages as data).
"""

from __future__ import annotations

import functools
import hashlib
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import sympy as sp
from sympy.printing.codeprinter import PrintMethodNotImplementedError
from sympy.printing.jscode import JavascriptCodePrinter

from mechanics.numeric import CompiledScene, _args, _plain

#: ``Math``'s members the printer may use (sympy's JavaScript printer maps sin, Abs, sign, ...).
MATH_MEMBERS = frozenset(
    {
        "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh",
        "acosh", "atanh", "exp", "log", "sqrt", "cbrt", "abs", "sign", "pow", "min", "max",
        "floor", "ceil", "PI", "E", "SQRT2", "SQRT1_2", "LN2", "LN10", "LOG2E", "LOG10E",
    }
)  # fmt: skip
#: Names a printed expression may contain besides ``Math.<member>``: slots and temporaries.
_SLOT = re.compile(r"\b(?:y|p|a|b)\[\d+\]")
_NUMBER = re.compile(r"(?<![\w.])(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?")
_TEMP = re.compile(r"x\d+")
_IDENTIFIER = re.compile(r"[A-Za-z_$][\w$]*")
#: What is left of an expression once numbers, slots and names are taken out: operators only
#: (a Piecewise prints as a ternary with comparisons).
_OPERATORS = re.compile(r"[\s()+\-*/<>=!?:&|,]*")
#: '=' only inside a comparison (==, !=, <=, >=): an expression never assigns.
_ASSIGNMENT = re.compile(r"(?<![=!<>])=(?!=)|===?=")


class JsUnavailable(ValueError):
    """The derivation holds something the JavaScript printer cannot print safely."""


def checked_expression(code: str) -> str:
    """``code`` when it names nothing but Math's members, slots (``y[3]``, ``p[0]``), the time
    ``t`` and temporaries (``x7``), between numbers and operators; else JsUnavailable.

    This is the gate every printed expression passes before it reaches a page: a sympy function
    without a JavaScript twin, a symbol that escaped the slot substitution, or anything textual
    (a quote, a brace, a semicolon, a comment) is refused here rather than served.
    """
    rest = _SLOT.sub(" ", code)
    rest = re.sub(r"\bMath\.(\w+)", lambda m: " " if m[1] in MATH_MEMBERS else m[0], rest)
    rest = _NUMBER.sub(" ", rest)
    for name in _IDENTIFIER.findall(rest):
        if name != "t" and not _TEMP.fullmatch(name):
            raise JsUnavailable(f"cannot generate JavaScript for '{name}'")
    rest = _IDENTIFIER.sub(" ", rest)
    if not _OPERATORS.fullmatch(rest) or _ASSIGNMENT.search(rest):
        odd = sorted(set(_OPERATORS.sub("", rest)))
        raise JsUnavailable(f"unexpected characters in generated JavaScript: {''.join(odd)!r}")
    return code


class _Printer(JavascriptCodePrinter):
    """JavaScript with small integer powers as products (Math.pow is a call; x*x is not)."""

    def _print_Pow(self, expr):  # noqa: N802 (sympy's printer protocol)
        base, exp = expr.base, expr.exp
        if exp.is_Integer and 1 < abs(int(exp)) <= 4:
            b = self.parenthesize(base, 100)
            prod = "*".join([b] * abs(int(exp)))
            return f"({prod})" if exp > 0 else f"(1/({prod}))"
        if exp == -1:
            return f"(1/{self.parenthesize(base, 100)})"
        return super()._print_Pow(expr)


def _number(e: object) -> sp.Basic:
    """Sympy expressions pass; plain numbers become sympy numbers (never text: no sympify)."""
    if isinstance(e, sp.Basic):
        return e
    return sp.Integer(e) if isinstance(e, int) else sp.Float(float(e))


def _function(name: str, outputs: list[str], temps: list, reduced: list, printer) -> list[str]:
    """One exported function: its temporaries, then ``target = expression;`` per output."""
    lines = [f"export function {name}(t, y, p, out) {{"]
    lines += [f"  const {s} = {checked_expression(printer.doprint(e))};" for s, e in temps]
    lines += [
        f"  {target} = {checked_expression(printer.doprint(e))};"
        for target, e in zip(outputs, reduced, strict=True)
    ]
    return lines


def _cse(exprs: Sequence[sp.Basic]) -> tuple[list, list]:
    return sp.cse(list(exprs), symbols=sp.numbered_symbols("x"))


_SOLVE = """\
// Gaussian elimination with partial pivoting, in place: a (n×n, row-major) x = b -> b.
function solve(n, a, b) {
  for (let c = 0; c < n; c++) {
    let piv = c;
    for (let r = c + 1; r < n; r++) if (Math.abs(a[r * n + c]) > Math.abs(a[piv * n + c])) piv = r;
    if (!(Math.abs(a[piv * n + c]) > 0)) return 1;
    if (piv !== c) {
      for (let j = 0; j < n; j++) {
        const s = a[c * n + j]; a[c * n + j] = a[piv * n + j]; a[piv * n + j] = s;
      }
      const s = b[c]; b[c] = b[piv]; b[piv] = s;
    }
    for (let r = c + 1; r < n; r++) {
      const m = a[r * n + c] / a[c * n + c];
      for (let j = c; j < n; j++) a[r * n + j] -= m * a[c * n + j];
      b[r] -= m * b[c];
    }
  }
  for (let r = n - 1; r >= 0; r--) {
    let s = b[r];
    for (let j = r + 1; j < n; j++) s -= a[r * n + j] * b[j];
    b[r] = s / a[r * n + r];
  }
  return 0;
}
"""


@dataclass(frozen=True)
class LiveModule:
    """The module's text, its content hash (its URL's version), and the names of its slots."""

    source: str
    digest: str
    coordinates: list[str]
    parameters: list[str]
    points: list[str]
    frames: list[str]
    solved: bool
    extras: int
    #: The stops the module's ``stops`` evaluates, in its order: name, message, crossing.
    stops: list[dict] = field(default_factory=list)
    #: Stops the preview cannot watch (on a tension): their names.
    unwatched: list[str] = field(default_factory=list)

    def slots(self) -> dict:
        """The names of its slots, as the API and the page's inline data carry them."""
        return {
            "coordinates": self.coordinates,
            "parameters": self.parameters,
            "points": self.points,
            "frames": self.frames,
            "solved": self.solved,
            "extras": self.extras,
            "stops": self.stops,
            "unwatched_stops": self.unwatched,
        }


def live_module(c: CompiledScene) -> LiveModule:
    """Print the scene's right-hand side, positions, frame axes and energies as an ES module."""
    d = c.derivation
    m, w = d.model, d.work
    args, subs = _args(d)
    n = c.n
    slots = {args[0]: sp.Symbol("t")}
    slots |= {a: sp.Symbol(f"y[{i}]") for i, a in enumerate(args[1 : 2 * n + 1])}
    slots |= {a: sp.Symbol(f"p[{k}]") for k, a in enumerate(args[2 * n + 1 :])}

    def slotted(exprs: Sequence[object]) -> list[sp.Basic]:
        out = [_number(_plain(e, subs) if isinstance(e, sp.Basic) else e) for e in exprs]
        out = [e.xreplace(slots) for e in out]
        stray = set().union(*(e.free_symbols for e in out)) - set(slots.values())
        if stray:
            raise JsUnavailable(f"unexpected symbols {sorted(map(str, stray))}")
        return out

    inputs = c.native_inputs  # the plain (already slot-free of q(t)) expressions numeric compiles
    rates = list(inputs["power"])
    printer = _Printer({"strict": True})
    try:
        if c.solved:
            exprs = slotted([*inputs["accelerations"], *rates])
            temps, reduced = _cse(exprs)
            outs = [f"out[{n + i}]" for i in range(n)]
        else:
            exprs = slotted([*inputs["mass"], *inputs["forcing"], *rates])
            temps, reduced = _cse(exprs)
            outs = [f"a[{i}]" for i in range(n * n)] + [f"b[{i}]" for i in range(n)]
        outs += [f"out[{2 * n + i}]" for i in range(len(rates))]
        rhs = _function("rhs", outs, temps, reduced, printer)
        rhs += [f"  out[{i}] = y[{n + i}];" for i in range(n)]
        if not c.solved:
            rhs += [
                f"  if (solve({n}, a, b)) return 2;",
                *(f"  out[{n + i}] = b[{i}];" for i in range(n)),
            ]
            rhs.insert(1, f"  const a = new Float64Array({n * n}), b = new Float64Array({n});")
        rhs += ["  return 0;", "}"]

        points = list(m.positions)
        vecs = [m.positions[k].dot(u) for k in points for u in (m.N.x, m.N.y, m.N.z)]
        temps, reduced = _cse(slotted(vecs))
        places = _function(
            "places", [f"out[{i}]" for i in range(len(vecs))], temps, reduced, printer
        )
        places.append("}")

        frames = list(m.frames)
        comps = [
            getattr(m.frames[f].frame, a).dot(u)
            for f in frames
            for a in "xyz"
            for u in (m.N.x, m.N.y, m.N.z)
        ]
        temps, reduced = _cse(slotted(comps))
        axes = _function("axes", [f"out[{i}]" for i in range(len(comps))], temps, reduced, printer)
        axes.append("}")

        temps, reduced = _cse(slotted([w.T, w.V]))
        energy = _function("energy", ["out[0]", "out[1]"], temps, reduced, printer)
        energy.append("}")

        watched = [st for st in m.stops if st.when is not None]
        unwatched = [st.name for st in m.stops if st.when is None]
        conds = [e for st in watched for e in (st.when, 1 if st.only_if is None else st.only_if)]
        temps, reduced = _cse(slotted(conds))
        stops = _function(
            "stops", [f"out[{i}]" for i in range(len(conds))], temps, reduced, printer
        )
        stops.append("}")
    except PrintMethodNotImplementedError as exc:
        raise JsUnavailable(f"cannot generate JavaScript: {str(exc).splitlines()[0]}") from exc

    dims = (
        f"export const dims = {{ n: {n}, extras: {len(rates)}, params: {len(c.parameters)}, "
        f"points: {len(points)}, frames: {len(frames)}, stops: {len(watched)} }};"
    )
    source = "\n".join(
        [
            "// Generated by Lagrange Lab (mechanics/jscode.py) from a scene's derivation: the",
            "// equations of motion over numbered slots, for the live preview (static/js/live.js).",
            dims,
            "" if c.solved else _SOLVE,
            *rhs,
            *places,
            *axes,
            *energy,
            *stops,
            "",
        ]
    )
    return LiveModule(
        source=source,
        digest=hashlib.sha256(source.encode()).hexdigest()[:16],
        coordinates=list(c.coordinates),
        parameters=list(c.parameters),
        points=points,
        frames=frames,
        solved=c.solved,
        extras=len(rates),
        stops=[{"name": st.name, "message": st.message, "crossing": st.crossing} for st in watched],
        unwatched=unwatched,
    )


@functools.lru_cache(maxsize=64)
def scene_live_module(scene_id: str) -> LiveModule:
    """A built-in scene's module, printed once per process (cse of a double pendulum's
    expressions takes a fraction of a second; the page asks for it on every visit)."""
    from mechanics.numeric import compiled_scene

    return live_module(compiled_scene(scene_id))


def posted_live_json(key: str) -> dict:
    """A posted spec's module and slot names (``key``: its canonical JSON, mechanics/jobs.py's
    spec_key), for a pool worker: the spec is user input, derived under the pool's budget."""
    import json

    from mechanics.numeric import compiled_spec

    live = live_module(compiled_spec(json.loads(key)))
    return {"source": live.source, "digest": live.digest, **live.slots()}
