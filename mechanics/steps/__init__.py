"""The derivation, one module per step of the notes' procedure (IV.A 1–6).

A step is a function ``(model, work) -> Step``: it reads the quantities earlier steps left in
``work`` (T, V, Q_j, ...) and adds its own, so every quantity is computed exactly once.
"""

from __future__ import annotations

import functools
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any

import sympy as sp
from sympy.physics.vector import Vector
from sympy.simplify.fu import TR5, TR6, TR8, TR10i

from mechanics.expr import to_latex, to_plain
from mechanics.steps.radicals import radicals, tidy_radical

#: Expressions larger than this (count_ops) skip trigsimp: it is the step that can take minutes.
SIMPLIFY_OPS_BUDGET = 600
#: Up to this size sympy's full trigsimp is affordable (for tan/cot/sec/csc identities).
SMALL_OPS = 16
#: A sum of more terms than this is left as it is: no textbook prints one.
MAX_TERMS = 100
#: A sum past either size gets the trig pass group by group (see _large_sum): more terms than
#: LARGE_TERMS, or more than LARGE_TERMS_X_SYMBOLS terms × free symbols (factor() works in every
#: symbol at once). Every piece of the built-in scenes stays below both: they keep the whole-sum
#: pass, whose forms are the hand-checked ones.
LARGE_TERMS = 6
LARGE_TERMS_X_SYMBOLS = 24


#: Pieces left unsimplified because they were over budget, per derivation (per thread/task).
unsimplified: ContextVar[list] = ContextVar("unsimplified")


@dataclass
class Line:
    """One displayed equation: a label, its LaTeX and its plain-text form."""

    label: str
    latex: str
    plain: str


@dataclass
class Step:
    id: str
    title: str
    text: str
    lines: list[Line] = field(default_factory=list)
    data: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "title": self.title,
            "text": self.text,
            "latex": [ln.latex for ln in self.lines],
            "plain": [ln.plain for ln in self.lines],
            "labels": [ln.label for ln in self.lines],
            "data": self.data,
        }


@dataclass
class Work:
    """What the steps have derived so far, and what could not be simplified in budget.

    No clock in here: every budget a step applies is a size (count_ops, terms, coordinates), so
    the derivation is a function of the spec alone (only budget.py's outer deadline, which fails
    a request, reads the clock)."""

    T: sp.Expr = sp.S.Zero
    V: sp.Expr = sp.S.Zero
    L: sp.Expr = sp.S.Zero
    Q: list[sp.Expr] = field(default_factory=list)
    eom_lhs: list[sp.Expr] = field(default_factory=list)
    momenta: list[sp.Expr] = field(default_factory=list)  # ∂L/∂q̇_j
    dL_dq: list[sp.Expr] = field(default_factory=list)  # ∂L/∂q_j
    mass_matrix: sp.Matrix | None = None
    forcing: sp.Matrix | None = None
    accelerations: list[sp.Expr] | None = None
    conserved: list[dict[str, Any]] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)


def tidy(
    expr: sp.Expr, model: Any = None, *, collect_velocities: bool = True, factor_whole: bool = True
) -> sp.Expr:
    """Textbook form: trig identities applied, terms grouped by velocity monomial.

    Small pieces are simplified one at a time (the issue's lesson: simplifying a solved q̈ whole
    is where the minutes go): the expression is split by velocity monomial and each coefficient
    gets a cheap trig pass. Past the size budget a coefficient is left expanded: still correct,
    only less pretty.
    """
    expr = sp.Integer(expr) if isinstance(expr, int) else expr
    if expr.is_number:
        return sp.nsimplify(expr) if expr.is_Float else expr
    if model is None:
        return _flagged(_tidy_symbols(expr, (), factor_whole))
    to_sym, back = _symbols_for(model)
    velocities = tuple(to_sym[v] for v in (*model.qdd, *model.qd)) if collect_velocities else ()
    return _flagged(_tidy_symbols(expr.xreplace(to_sym), velocities, factor_whole)).xreplace(back)


def partial(expr: sp.Expr, var: sp.Expr, model: Any) -> sp.Expr:
    """∂expr/∂var for var one of q, q̇, q̈ (or t, explicit only), on plain symbols.

    Differentiating with respect to q(t) inside sympy walks every term through the chain rule
    for functions of t; on plain symbols it is a polynomial operation, several times faster.
    """
    to_sym, back = _symbols_for(model)
    plain = expr.xreplace(to_sym)
    return plain.diff(to_sym.get(var, var)).xreplace(back)


def d_dt(expr: sp.Expr, model: Any) -> sp.Expr:
    """Total time derivative: Σ ∂/∂q q̇ + ∂/∂q̇ q̈ + ∂/∂t (the notes' d/dt ∂L/∂q̇_j)."""
    to_sym, back = _symbols_for(model)
    plain = expr.xreplace(to_sym)
    t = model.names["t"]
    total = plain.diff(t)
    for q, qd, qdd in zip(model.q, model.qd, model.qdd, strict=True):
        total += plain.diff(to_sym[q]) * to_sym[qd] + plain.diff(to_sym[qd]) * to_sym[qdd]
    return total.xreplace(back)


def _symbols_for(model: Any) -> tuple[dict, dict]:
    """q(t), q̇(t), q̈(t) as plain symbols: trig passes run faster on symbols than on functions."""
    cached = getattr(model, "_tidy_symbols", None)
    if cached is None:
        to_sym = {}
        for i, (q, qd, qdd) in enumerate(zip(model.q, model.qd, model.qdd, strict=True)):
            assume = {"positive": True} if q.is_positive else {"real": True}
            to_sym[qdd] = sp.Symbol(f"_qdd{i}", real=True)
            to_sym[qd] = sp.Symbol(f"_qd{i}", real=True)
            to_sym[q] = sp.Symbol(f"_q{i}", **assume)
        cached = (to_sym, {v: k for k, v in to_sym.items()})
        model._tidy_symbols = cached
    return cached


#: What a cached simplification returns: the expression, and the pieces it left unsimplified.
Tidied = tuple[sp.Expr, tuple[sp.Expr, ...]]


@functools.lru_cache(maxsize=4096)
def _tidy_symbols(expr: sp.Expr, velocities: tuple, factor_whole: bool = True) -> Tidied:
    """tidy() on plain symbols. Cached across derivations, so it returns the pieces it left
    unsimplified instead of reporting them: a cache hit must flag exactly what a miss flags."""
    roots = radicals(expr)
    if roots:  # roots of sums (not 1/(a + b)): see steps/radicals.py
        return tidy_radical(expr, roots, velocities, _trig_pass, _size, factor_whole)
    e = sp.expand(expr)
    if e == 0:
        return e, ()
    if e.is_Add and len(e.args) > MAX_TERMS:
        return e, (e,)  # far past the budget: even grouping it costs more than it can gain
    if velocities:
        groups = sp.collect(e, velocities, evaluate=False)
        if len(groups) > 1 or 1 not in groups:
            passes = [(_trig_pass(c), m) for m, c in groups.items()]
            total = sp.Add(*(c * m for (c, _), m in passes))
            skipped = tuple(p for (_, flags), _ in passes for p in flags)
            if factor_whole:
                total = min((total, sp.factor_terms(total)), key=_size)
            return total, skipped
    return _trig_pass(e)


def _flagged(tidied: Tidied) -> sp.Expr:
    """Report the pieces a (possibly cached) simplification left alone; return its result."""
    expr, skipped = tidied
    for piece in skipped:
        _flag(piece)
    return expr


def _flag(e: sp.Expr) -> None:
    skipped = unsimplified.get(None)
    if skipped is not None and e not in skipped:  # a piece counts once, however often it recurs
        skipped.append(e)


def _positive_lead(e: sp.Expr) -> sp.Expr:
    """−R m (g − Ω² R cos θ) sin θ  →  R m (Ω² R cos θ − g) sin θ: move a minus into a sum."""
    if not e.is_Mul or not e.could_extract_minus_sign():
        return e
    sums = [f for f in e.args if f.is_Add]
    if not sums:
        return e
    target = max(sums, key=lambda a: sum(1 for t in a.args if t.could_extract_minus_sign()))
    negatives = sum(1 for t in target.args if t.could_extract_minus_sign())
    if 2 * negatives + 1 < len(target.args):
        return e
    rest = [f for f in e.args if f is not target]
    return sp.Mul(*rest) * -1 * sp.expand(-target)


def _size(e: sp.Expr) -> tuple[int, int]:
    """Printed size: operations, then tree nodes (printing to measure would cost 4× more)."""
    return sp.count_ops(e), sum(1 for _ in sp.preorder_traversal(e))


@functools.lru_cache(maxsize=4096)
def _trig_pass(c: sp.Expr) -> Tidied:
    """sin²+cos² = 1 and products to sums of angles, keeping whichever form is smallest.

    Cached: T, L, E and the Jacobi integral share most of their coefficients. A piece over the
    size budget comes back as it is, and as skipped (see _tidy_symbols)."""
    c = sp.expand(c)
    if sp.count_ops(c) > SIMPLIFY_OPS_BUDGET:
        return c, (c,)
    if c.is_Add and _is_large(c):
        return _large_sum(c)
    return _trig_identities(c), ()


def _is_large(c: sp.Add) -> bool:
    terms = len(c.args)
    return terms > LARGE_TERMS or terms * len(c.free_symbols) > LARGE_TERMS_X_SYMBOLS


def _large_sum(c: sp.Add) -> Tidied:
    """The trig pass of a sum of many terms (a chain of 3+ links), in two small passes.

    On the whole sum TR10i tries every pair of terms and factor() works in every symbol at once:
    seconds per piece. But an identity only ever joins terms with the same trig-free coefficient
    (m l² sin² + m l² cos² = m l²), so each coefficient's trig part is simplified alone; then the
    terms with the same trig part are gathered and their trig-free coefficient factored:
    l1 m2 cos θ1 + l1 m3 cos θ1 → l1 (m2 + m3) cos θ1.
    """
    by_coefficient: dict[sp.Expr, list[sp.Expr]] = {}
    for term in c.args:
        coefficient, trig = _split_trig(term, numbers_with_trig=True)
        by_coefficient.setdefault(coefficient, []).append(trig)
    passes = [(k, _trig_group(sp.Add(*trigs))) for k, trigs in by_coefficient.items()]
    skipped = tuple(p for _, (_, flags) in passes for p in flags)
    by_trig: dict[sp.Expr, list[sp.Expr]] = {}
    for term in sp.Add.make_args(sp.expand(sp.Add(*(k * e for k, (e, _) in passes)))):
        coefficient, trig = _split_trig(term)
        by_trig.setdefault(trig, []).append(coefficient)
    total = sp.Add(*(sp.factor(sp.Add(*ks)) * trig for trig, ks in by_trig.items()))
    return _positive_lead(sp.factor_terms(total)), skipped


@functools.lru_cache(maxsize=4096)
def _trig_group(c: sp.Expr) -> Tidied:
    """The whole-sum pass on one group of _large_sum (never split again: its terms share one
    coefficient already)."""
    if sp.count_ops(c) > SIMPLIFY_OPS_BUDGET:
        return c, (c,)
    return _trig_forms(c), ()


def _split_trig(term: sp.Expr, numbers_with_trig: bool = False) -> tuple[sp.Expr, sp.Expr]:
    """A product as (trig-free coefficient, the factors with a function in them).

    With ``numbers_with_trig`` the number goes with the trig part, so that m² cos²a,
    −2 m² cos a cos b and m² fall in one group, where sums like 1 − cos²a can cancel."""
    coefficient, trig = [], []
    for f in sp.Mul.make_args(term):
        goes_with_trig = f.has(sp.Function) or (numbers_with_trig and f.is_Number)
        (trig if goes_with_trig else coefficient).append(f)
    return sp.Mul(*coefficient), sp.Mul(*trig)


def _trig_identities(c: sp.Expr) -> sp.Expr:
    """The whole-sum trig pass proper, on a piece within the size budget."""
    if c.has(sp.tan, sp.cot, sp.sec, sp.csc) and sp.count_ops(c) <= SMALL_OPS:
        c = min((c, sp.trigsimp(c)), key=_size)  # small: trigsimp is cheap here
    if c.has(sp.sin, sp.cos):
        candidates = [c, *_squares_rewritten(c)]
        joined: dict[sp.Expr, sp.Expr] = {}  # TR10i once per distinct form
        for x in candidates[:3]:
            if x not in joined:
                joined[x] = sp.expand(TR10i(x))
        candidates += [joined[x] for x in candidates[:3]]
        candidates += [sp.expand(TR8(c)), sp.expand(sp.expand_trig(c))]
        c = TR10i(min(candidates, key=_size))
    return _factored(c)


def _trig_forms(c: sp.Expr) -> sp.Expr:
    """The trig pass of one group of _large_sum, expanded (the caller gathers and factors).

    Fewer forms than the whole-sum pass: on the groups of a triple pendulum, a heavy top and a
    six-link chain the smallest form was always c itself, TR6, TR10i or TR8 (products to sums)."""
    if not c.has(sp.sin, sp.cos):
        return c
    candidates = [c, *_squares_rewritten(c)]
    candidates += [sp.expand(TR10i(c)), sp.expand(TR8(c))]
    return sp.expand(TR10i(min(candidates, key=_size)))


def _squares_rewritten(c: sp.Expr) -> list[sp.Expr]:
    """c with sin² → 1 − cos² (TR5) and with cos² → 1 − sin² (TR6), expanded. Without a square
    of a sine or cosine both leave c as it is: then it is expanded once, not transformed twice
    and the copy's TR10i taken thrice (a third of the trig pass on a 3-D chain's pieces)."""
    if not any(p.exp.is_Integer and p.exp >= 2 for p in c.atoms(sp.Pow) if p.base.func in TRIG):
        same = sp.expand(c)
        return [same, same]
    return [sp.expand(TR5(c)), sp.expand(TR6(c))]


TRIG = (sp.sin, sp.cos)


def _factored(c: sp.Expr) -> sp.Expr:
    """A sum with its common factors out, and a minus sign moved into it where that reads better."""
    if not c.is_Add:
        return c
    if len(c.args) < 3:  # a common factor of two terms is all there is to find
        return _positive_lead(sp.factor_terms(c))
    factored = _positive_lead(sp.factor_terms(sp.factor(c)))
    if factored.is_Mul:
        return factored
    # A sum with no common factor may still share one within some terms: k*l0 - k*r = k*(l0 - r).
    shared = [s for s in c.free_symbols if sum(1 for a in c.args if a.has(s)) >= 2]
    shapes = [factored] + [sp.collect(c, s) for s in sorted(shared, key=str)[:4]]
    return min(shapes, key=_size)


def vec_in(vector: Vector, frame_name: str, model: Any) -> tuple[Vector, list[sp.Expr]]:
    """A vector written along one frame's unit vectors, each component tidied."""
    frame = model.frame(frame_name)
    comps = [tidy(vector.dot(u), model) for u in (frame.x, frame.y, frame.z)]
    out = Vector(0)
    for c, u in zip(comps, (frame.x, frame.y, frame.z), strict=True):
        out += c * u
    return out, comps


def vec_line(label_latex: str, vector: Vector, frame_name: str, model: Any, label: str) -> Line:
    v, comps = vec_in(vector, frame_name, model)
    names = model.plain_vectors(frame_name)
    plain = ""
    for c, n in zip(comps, names, strict=True):
        if c == 0:
            continue
        negative = c.could_extract_minus_sign() and not c.is_Add
        text = to_plain(-c if negative else c)
        term = f"({text})*{n}" if c.is_Add else f"{text}*{n}"
        plain += (
            (" - " if negative else " + ") + term if plain else ("-" if negative else "") + term
        )
    return Line(label, rf"{label_latex} = {to_latex(v) if plain else '0'}", plain or "0")


def sub(name: str) -> str:
    """A body or frame name as a LaTeX subscript: upright text when it is a word."""
    return name if len(name) == 1 else rf"\text{{{name}}}"


def eq_line(label: str, lhs_latex: str, expr: sp.Expr, lhs_plain: str | None = None) -> Line:
    return Line(
        label, f"{lhs_latex} = {to_latex(expr)}", f"{lhs_plain or label} = {to_plain(expr)}"
    )
