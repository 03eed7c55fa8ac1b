"""Is a student's T, V, L, Q_j, equation of motion, q̈ or p_j right — and if not, where is it wrong?

Equivalence is decided at random states (parameters near their defaults, random q, q̇, q̈, t),
backed by symbolic simplification, so `1 - cos(x)**2` equals `sin(x)**2` however it is written.
A wrong answer is compared term by term with the derived one, after both are brought to one
canonical form (trig of single coordinates, sin² written as 1 − cos²): what is missing, what is
extra, which term has its sign flipped or a wrong factor; then the usual slips are tried (two
parameters swapped, q mixed up with q̇) and the units of every term are checked.
"""

from __future__ import annotations

import cmath
import itertools
import math
import random
import re
from dataclasses import dataclass, field
from decimal import Decimal, localcontext
from typing import Any

import sympy as sp
from sympy.simplify.fu import TR5

from mechanics import check_approximations as approximations
from mechanics import units
from mechanics.answers import read_answer
from mechanics.check_identities import (  # noqa: F401  (re-exported: the proofs' budget)
    MAX_NORMAL_TERMS,
    MAX_TRIG_MULTIPLE,
    PROOF_OPS,
    zero_by_algebra,
)
from mechanics.check_identities import expansion_size as _expansion_size
from mechanics.check_potential import missing_potential
from mechanics.check_slips import sign_in_group, sign_of_a_term
from mechanics.derive import Derivation
from mechanics.expr import parse
from mechanics.expr import to_latex as _latex_of
from mechanics.model import T as t
from mechanics.spec import SpecError
from mechanics.steps import _symbols_for, partial, tidy

QUANTITIES = ("T", "V", "L", "Q", "eom", "accel", "momentum")
PER_COORDINATE = {"Q", "eom", "accel", "momentum"}
SAMPLES = 12
MAX_UNIT_LINES = 4
MAX_TERMS = 40  # past this many monomials, feedback term by term would not help anyone
TOLERANCE = 1e-9
#: Past PROOF_OPS, up to this size, only the evaluation at exact random points is tried (a
#: solved q̈ of the double pendulum, typed out expanded, is 533 operations).
MAX_PROOF_OPS = 4000
#: No proof past this exponent: exact rationals to the 10⁴th power are megabytes of digits.
MAX_PROOF_POWER = 256
#: sympy's general simplify() is the last resort, and only this small (it is the slow one).
SIMPLIFY_OPS = 60
#: |·| and sign() are settled by trying both signs of their argument: 2**k cases for k of them.
MAX_SIGN_CASES = 3
#: A number typed within this relative distance of a simple one (a fraction with a denominator
#: up to NEAR_MISS_DENOMINATOR) is a near miss of it: 1.9999999999 of 2, 0.49999999999 of 1/2.
NEAR_MISS = 1e-6
#: Feedback term by term expands sin(n θ) only up to this n (the proofs stop at
#: MAX_TRIG_MULTIPLE): sin(10¹⁴ θ) expanded would never finish.
MAX_CANONICAL_MULTIPLE = 64
NEAR_MISS_DENOMINATOR = 1000
#: A group of terms is restated in the student's own terms only if changing at most this many
#: of them (trying at most MAX_CHANGE_TRIES sets) says what differs.
MAX_CHANGED_TERMS = 3
MAX_CHANGE_TRIES = 64
#: F of a total derivative dF/dt is integrated only from polynomials up to this degree.
MAX_INTEGRATED_POWER = 8


def _never_zero(factor: sp.Expr) -> bool:
    """Is ``factor`` a number times powers of parameters (1/(m l²)), which no parameter value
    but 0 makes vanish? (m₁ − m₂)/(m₁ + m₂) is 0 at m₁ = m₂: scaling by it hides the equation."""
    for part in sp.Mul.make_args(sp.factor(factor)):
        base = part.as_base_exp()[0]
        if not (base.is_number or base.is_Symbol):
            return False
    return factor != 0


def _sign_definite(factor: sp.Expr, model: Any) -> bool:
    """Is ``factor`` provably non-zero and finite at every state the scene reaches (2 + sin²θ₁;
    1/(m r) with r declared positive)? Then multiplying an equation of motion by it loses and
    adds no solution. Decided by sympy's sign rules, factor by factor, under the scene's own
    assumptions: coordinates declared positive are positive, and parameters that are magnitudes
    (a mass, a length) are taken positive, as `_never_zero` takes them for a constant factor
    (at 0 the derived equation itself degenerates). Anything sympy cannot settle is not
    definite: the caller keeps the cautious verdict."""
    if factor.has(*model.qdd) or sp.count_ops(factor) > SIMPLIFY_OPS:
        return False
    to_sym, _ = _symbols_for(model)
    plain = factor.xreplace(to_sym)
    plain = plain.xreplace(
        {s: sp.Symbol(s.name, positive=True) for s in plain.free_symbols if s.is_nonnegative}
    )
    # one form may show it where another does not ((2 + sin²θ₁)(sin²θ₂ + cos²θ₂) once cos² is
    # read as 1 − sin²): each is the same expression, so any one proof is sound
    forms = (plain, sp.trigsimp(plain), _tidy(plain, model))
    return any(
        all(part.is_positive or part.is_negative for part in sp.Mul.make_args(sp.factor(form)))
        for form in forms
    )


#: How a verdict that no proof could settle begins (`Verdict.confirmed`).
UNCONFIRMED = "Not confirmed"


@dataclass
class Verdict:
    correct: bool
    feedback: list[str] = field(default_factory=list)
    answer_latex: str = ""
    expected_latex: str = ""

    @property
    def confirmed(self) -> bool:
        """False when the samples agree but no proof could tell: neither right nor wrong is
        claimed (the page says 'not confirmed', not 'not yet')."""
        return not any(line.startswith(UNCONFIRMED) for line in self.feedback)

    def to_json(self, reveal: bool) -> dict[str, Any]:
        out = {
            "correct": self.correct,
            "confirmed": self.confirmed,
            "feedback": self.feedback,
            "answer_latex": self.answer_latex,
        }
        if reveal:
            out["expected_latex"] = self.expected_latex
        return out


def _huge_multiple(expr: sp.Expr) -> bool:
    """Does ``expr`` hold sin(n θ) (or cos, tan, ...) with an integer n past
    MAX_CANONICAL_MULTIPLE? Expanding it is a Chebyshev polynomial of degree n: never for 10¹⁴."""
    return any(
        n.is_Integer and abs(n) > MAX_CANONICAL_MULTIPLE
        for f in expr.atoms(sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)
        for n in (a.as_coeff_Mul()[0] for a in sp.Add.make_args(f.args[0]))
    )


def _tidy(expr: sp.Expr, model: Any, **options: Any) -> sp.Expr:
    """The derivation's tidy(), which expands trig: an answer's sin(10¹⁴ θ) is left as typed."""
    return expr if _huge_multiple(expr) else tidy(expr, model, **options)


def zero_proof(expr: sp.Expr, model: Any) -> bool | None:
    """Is ``expr`` identically zero? True or False only on an exact argument, None when sympy
    cannot tell within the size budget.

    Samples cannot decide it: exp(−10⁶ θ̇²) or 10⁻³⁰ θ is zero at every state a check samples,
    and is still a term the derived result does not have. The argument: numbers as typed
    (0.1 is 1/10), |a| and sign(a) settled for each sign of a, tan/sec/... written with sin and
    cos, trig of sums and multiples expanded to sin and cos of single coordinates, then the
    numerator of the whole reduced with sin² = 1 − cos². What is left is a polynomial in
    algebraically independent functions (q, sin q, cos q taken once, q̇, q̈, t, parameters): zero
    exactly when the expression is. Outside that class (exp, log, sqrt of a variable, trig of
    w t ...) only sympy's simplify() can show a zero, and nothing is claimed non-zero.
    """
    ops = sp.count_ops(expr)
    if ops > MAX_PROOF_OPS or _max_power(expr) > MAX_PROOF_POWER:
        return None
    # expanding is what normal forms cost: past a small expansion, only exact evaluation
    small = ops <= PROOF_OPS and _expansion_size(expr, MAX_NORMAL_TERMS) <= MAX_NORMAL_TERMS
    to_sym, _ = _symbols_for(model)
    e = expr.xreplace(to_sym)
    # a Float left (a spec's 15-digit parameter) is the exact decimal it prints as: 1e-12 is
    # 1/10**12, 1.9999999999 is not 2 (nsimplify would snap it to the nearest simple number)
    e = e.xreplace({f: sp.Rational(str(f)) for f in e.atoms(sp.Float)})
    cases = _sign_cases(e, _positive_in_domain(model))
    if cases is None:
        return None
    results = [zero_by_algebra(c, small) for c in cases]
    if all(r is True for r in results):
        return True
    if len(cases) == 1 and results[0] is False:
        return False  # with a case split, a non-zero branch may be one no state reaches
    if small and _tidy(expr, model) == 0:  # trig beside exp or sqrt: the derivation's own pass
        return True
    if (
        small
        and len(cases) == 1
        and sp.count_ops(e) <= SIMPLIFY_OPS
        and not e.has(sp.sin, sp.cos, sp.tan)  # simplify()'s trig search is the minutes-long one
        and sp.simplify(e) == 0
    ):
        return True
    return None


def constant_proof(expr: sp.Expr, model: Any) -> bool | None:
    """Is ``expr`` free of q, q̇, q̈ and t (a constant of the motion's parameters)? Each of its
    partial derivatives put to zero_proof: True only if all are shown zero, False if one is
    shown non-zero."""
    to_sym, back = _symbols_for(model)
    plain = expr.xreplace(to_sym)
    results = []
    for sym in [*to_sym.values(), t]:
        if plain.has(sym):
            results.append(zero_proof(plain.diff(sym).xreplace(back), model))
    if all(r is True for r in results):
        return True
    return False if False in results else None


def _positive_in_domain(model: Any) -> tuple[sp.Expr, ...]:
    """What the scene's model keeps positive wherever it holds, as plain symbols: the value of
    each unguarded stop a run ends at (L0 + x for a spring that may not reach its anchor; a
    Piecewise's branch where the scene's parameters select it). |L0 + x| is L0 + x there, and
    an identity needs to hold only there."""
    cached = getattr(model, "_positive_in_domain", None)
    if cached is not None:
        return cached
    to_sym, _ = _symbols_for(model)
    values = {
        sym: sp.Rational(str(model.spec.parameters[name])) for name, sym in model.params.items()
    }
    out = []
    for value, guard in _domain_limits(model):
        if guard is not None:
            continue
        if isinstance(value, sp.Piecewise):
            branch, condition = value.args[0]
            if condition.xreplace(values) is not sp.true:
                continue
            value = branch
        out.append(value.xreplace(to_sym))
    model._positive_in_domain = tuple(out)
    return model._positive_in_domain


def _sign_cases(e: sp.Expr, positive: tuple[sp.Expr, ...] = ()) -> list[sp.Expr] | None:
    """``e`` with each |a| and sign(a) replaced for a ≥ 0 and for a < 0 (a at a pole of sign,
    a = 0, is one state among infinitely many and does not decide an identity); only a > 0
    where a is kept ``positive`` by the scene's domain. None past MAX_SIGN_CASES of them."""
    inner = sorted(e.atoms(sp.Abs, sp.sign), key=sp.default_sort_key)
    arguments = list(dict.fromkeys(f.args[0] for f in inner))
    if len(arguments) > MAX_SIGN_CASES:
        return None
    cases = [e]
    for a in arguments:
        mine = [f for f in inner if f.args[0] == a]
        split = []
        signs = (1,) if a in positive else (-1,) if -a in positive else (1, -1)
        for s in signs:
            resolved = {f: s * a if isinstance(f, sp.Abs) else sp.Integer(s) for f in mine}
            split += [c.xreplace(resolved) for c in cases]
        cases = split
    if any(c.has(sp.Abs, sp.sign) for c in cases):
        return None  # nested |·| whose argument changed with the outer one: not this argument
    return cases


def _max_power(e: sp.Expr) -> int:
    """The largest integer exponent in ``e`` (a tower (θ⁶⁴)⁶⁴ counts as written, 64)."""
    return max((abs(int(p.exp)) for p in e.atoms(sp.Pow) if p.exp.is_Integer), default=0)


def expected_quantity(d: Derivation, quantity: str, j: int | None) -> sp.Expr:
    w = d.work
    return {
        "T": lambda: w.T,
        "V": lambda: w.V,
        "L": lambda: w.L,
        "Q": lambda: w.Q[j],
        "eom": lambda: w.eom_lhs[j] - w.Q[j],
        "accel": lambda: d.solved_accelerations[j],
        "momentum": lambda: w.momenta[j],
    }[quantity]()


def check(d: Derivation, quantity: str, answer: str, coordinate: str | None = None) -> Verdict:
    """Judge one answer; raises SpecError (bad quantity/coordinate) or ExprError (unparseable)."""
    model = d.model
    if quantity not in QUANTITIES:
        raise SpecError([{"field": "quantity", "message": f"one of {', '.join(QUANTITIES)}"}])
    j = None
    if quantity in PER_COORDINATE:
        if coordinate not in model.coordinate_names:
            names = ", ".join(model.coordinate_names)
            what = "missing" if coordinate is None else f"'{coordinate}' is not a coordinate"
            raise SpecError(
                [
                    {
                        "field": "coordinate",
                        "message": f"{what}: {quantity} is asked per coordinate; give one of "
                        f"{names}",
                    }
                ]
            )
        j = model.coordinate_names.index(coordinate)
    expected = expected_quantity(d, quantity, j)
    given, moved = read_answer(d, quantity, answer, j, exact_decimals=True)
    shown = to_latex(given)
    if quantity == "eom":  # an equation reads as one: lhs = rhs as typed, or = 0
        shown = f"{to_latex(given + moved)} = {to_latex(moved)}"
    elif quantity == "accel":
        shown = f"{to_latex(d.model.qdd[j])} = {shown}"
    verdict = Verdict(False, answer_latex=shown, expected_latex=_latex(d, quantity, j))
    judge = _Judge(d, quantity, j, expected, given, moved)
    judge.typed_terms = _typed_terms(answer)
    judge.text = answer  # the brackets as typed: a sign slip is named in them (check_slips)
    judge.run(verdict)
    return verdict


def _typed_terms(answer: str) -> int:
    """How many terms the student typed at the top level (outside parentheses): sympy adds
    ½ m ẋ² + ½ (m R²)(ẋ/R)² into m ẋ² before the checker sees it, and whether they wrote one
    term or several decides if 'off by a factor' can be said of the whole."""
    count, depth, previous = 1, 0, ""
    for k, ch in enumerate(answer):
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch in "+-" and depth == 0 and previous not in ("", "(", "*", "/", "^", "=", "+", "-"):
            exponent = previous in "eE" and k >= 2 and answer[k - 2].isdigit()
            count += 0 if exponent else 1
        if not ch.isspace():
            previous = ch
    return count


def _parse_position(text: str, model: Any) -> sp.Expr:
    """A position component from the scene's file, read by the same whitelist parser."""
    return parse(text, model.names, field="position")


def _latex(d: Derivation, quantity: str, j: int | None) -> str:
    w, m = d.work, d.model
    if quantity == "eom":
        return f"{to_latex(w.eom_lhs[j])} = {to_latex(w.Q[j])}"
    if quantity == "accel":
        return f"{to_latex(m.qdd[j])} = {to_latex(d.solved_accelerations[j])}"
    return to_latex(expected_quantity(d, quantity, j))


#: A rational whose denominator is past this (and a power of 2 and 5 only) came from a decimal
#: the student typed, and is shown as one: 10^{-300}, not a fraction with 300 zeros; 2.000001,
#: not 2000001/1000000 (9.81 stays 981/100, as the derivations print it).
DECIMAL_DENOMINATOR = 1000


def to_latex(expr: sp.Expr) -> str:
    """LaTeX of an answer with its decimals shown as decimals: the checker reads 1.9999999999
    exactly (19999999999/10¹⁰), and the student should read back what they typed."""
    shown = {r: _as_decimal(r) for r in expr.atoms(sp.Rational) if _typed_decimal(r)}
    if not shown:
        return _latex_of(expr)
    return _POWER_OF_TEN.sub("10^", _latex_of(expr.xreplace(shown)))  # 10⁻³⁰⁰, not 1.0·10⁻³⁰⁰


_POWER_OF_TEN = re.compile(r"(?<![\d.])1\.0 \\cdot 10\^")


def _typed_decimal(r: sp.Rational) -> bool:
    q = int(r.q)
    if q <= DECIMAL_DENOMINATOR:
        return False
    for prime in (2, 5):
        while q % prime == 0:
            q //= prime
    return q == 1


def _as_decimal(r: sp.Rational) -> sp.Float:
    """The exact decimal of a rational p/(2ᵃ5ᵇ), as a Float holding all of its digits."""
    with localcontext() as context:
        context.prec = min(len(str(r.p)) + len(str(r.q)) + 2, MAX_SHOWN_DIGITS)
        decimal = (Decimal(int(r.p)) / Decimal(int(r.q))).normalize()
    return sp.Float(str(decimal), max(1, len(decimal.as_tuple().digits)))


#: The most significant digits a decimal is shown with (past them it is rounded, for reading).
MAX_SHOWN_DIGITS = 40


def inline(expr: sp.Expr) -> str:
    """Inline math for a feedback sentence: `$\\frac{g}{l} \\sin\\theta$` (the page renders it)."""
    return f"${to_latex(expr)}$"


def _as_written(term: sp.Expr) -> str:
    """A term of the answer as the student wrote it (no tidying: a power of a sum stays one);
    a term too big to read is named by its shape."""
    if sp.count_ops(term) > 40:
        return "you wrote as a long expression" if not term.is_Pow else "that is a power of a sum"
    return inline(term)


#: Random draws allowed per sampled state to find one inside the scene's domain.
DOMAIN_TRIES = 20


def _domain_limits(model: Any) -> list[tuple[sp.Expr, sp.Expr | None]]:
    """Where the scene's model holds, as its runs see it: each stop that ends a run when its
    value falls to 0 (a spring at its anchor, a position's domain end, a coordinate declared
    positive, a declared `when`), with its guard (`only_if`). A state where one of them is ≤ 0
    is one no run reaches, and an answer may differ from the derived one there (|L0 + x| for
    L0 + x): the checker samples, and claims, only inside. Stops on a tension (Newton's method
    at run time) and sign-change stops (friction) bound no region and are left out."""
    return [
        (stop.when, stop.only_if)
        for stop in model.stops
        if stop.when is not None and stop.crossing == "falls"
    ]


def _number_at(expr: sp.Expr, state: dict) -> float:
    """``expr`` at a state, as a float; NaN where it has no real value."""
    try:
        value = complex(expr.xreplace(state).evalf(20))
    except (TypeError, ValueError, ArithmeticError):
        return math.nan
    return value.real if abs(value.imag) <= 1e-12 * max(1.0, abs(value.real)) else math.nan


def scene_dimensions(model: Any) -> dict[sp.Expr, units.Dim]:
    """The units of every parameter, coordinate, its rates and t, from the scene's `units`;
    {} when the scene gives none (or not for all): then no term's units can be judged."""
    m = model
    dims: dict[sp.Expr, units.Dim] = {}
    try:
        for name, sym in m.params.items():
            if name in m.spec.units:
                dims[sym] = units.parse_unit(m.spec.units[name])
        for name, q, qd, qdd in zip(m.coordinate_names, m.q, m.qd, m.qdd, strict=True):
            if name not in m.spec.units:
                return {}
            base = units.parse_unit(m.spec.units[name])
            dims[q] = base
            dims[qd] = (base[0], base[1], base[2] - 1)
            dims[qdd] = (base[0], base[1], base[2] - 2)
    except units.UnitError:
        return {}
    dims[t] = (0, 0, 1)
    return dims if len(dims) >= len(m.params) + 3 * len(m.q) + 1 else {}


#: The units of a pure number, said so in feedback ("has units dimensionless" read badly).
NO_UNITS: units.Dim = (0, 0, 0)


class _Judge:
    def __init__(
        self,
        d: Derivation,
        quantity: str,
        j: int | None,
        expected: sp.Expr,
        given: sp.Expr,
        moved: sp.Expr = sp.S.Zero,
    ) -> None:
        self.d, self.m, self.quantity, self.j = d, d.model, quantity, j
        self.expected, self.given = expected, given
        self.moved = moved  # what the student wrote right of '=' (its terms changed sign)
        # what the units of every term should be: the quantity's, or for an equation of motion
        # the units of the student's own scaling of it (set in _eom)
        self.reference = expected
        self.scale: sp.Expr = sp.S.One  # the student's scaling of an equation of motion
        self.typed_terms = len(sp.Add.make_args(given))  # check() counts them in the text
        rng = random.Random(0)
        self.limits = _domain_limits(self.m)
        self.states = [self._inside_state(rng, {}) for _ in range(SAMPLES)]
        # The same motion states at one set of parameters: for "constant" and "multiple of",
        # which may depend on the parameters but not on q, q̇, q̈ or t.
        fixed = {sym: self.states[0][sym] for sym in self.m.params.values()}
        self.motion_states = [
            s if self._inside({**s, **fixed}) else self._inside_state(rng, fixed)
            for s in self.states
        ]
        self.motion_states = [{**s, **fixed} for s in self.motion_states]

    def _inside_state(self, rng: random.Random, fixed: dict) -> dict:
        """A random state where the scene's model holds (see `_domain_limits`), the parameters
        ``fixed`` kept; the last one drawn if none of a few is (no state is refused outright)."""
        for _ in range(DOMAIN_TRIES):
            state = {**self._state(rng), **fixed}
            if self._inside(state):
                break
        return state

    def _inside(self, state: dict) -> bool:
        """Does the model hold in ``state``: every limit's value > 0 where its guard applies?"""
        for value, guard in self.limits:
            if guard is not None and _number_at(guard, state) < 0:
                continue  # the stop does not apply here
            if not _number_at(value, state) > 0:  # NaN too: undefined is outside
                return False
        return True

    def _state(self, rng: random.Random) -> dict:
        m = self.m
        values: dict[Any, Any] = {}
        for name, sym in m.params.items():
            default = m.spec.parameters[name]
            values[sym] = (abs(default) or 1.0) * rng.uniform(0.6, 1.4)
        for q, qd, qdd in zip(m.q, m.qd, m.qdd, strict=True):
            values[qdd] = rng.uniform(-2, 2)
            values[qd] = rng.uniform(-2, 2)
            values[q] = rng.uniform(0.2, 1.3)
        values[t] = rng.uniform(0, 3)
        return {k: sp.Float(v, 30) for k, v in values.items()}

    def values(self, expr: sp.Expr, motion_only: bool = False) -> list[complex]:
        return self._values_at(expr, self.motion_states if motion_only else self.states)

    def _values_at(self, expr: sp.Expr, states: list[dict]) -> list[complex]:
        out = []
        for s in states:
            try:
                v = complex(expr.xreplace(s).evalf(25))
                abs(v)  # a modulus past double precision (1e308 + 1e308 i) raises here
            except (TypeError, ValueError, ArithmeticError, MemoryError):  # too many digits
                v = complex("nan")
            finite = math.isfinite(v.real) and math.isfinite(v.imag)
            out.append(v if finite else complex("nan"))  # beyond doubles: no number to compare
        return out

    def same(self, a: sp.Expr, b: sp.Expr) -> bool:
        for x, y in zip(self.values(a), self.values(b), strict=True):
            if not (abs(x - y) <= TOLERANCE * max(1.0, abs(x), abs(y))):
                return False
        return True

    def run(self, verdict: Verdict) -> None:
        q = self.quantity
        fb = verdict.feedback
        if all(cmath.isnan(v) for v in self.values(self.given)):
            fb.append(
                "Your answer has no value at any state sampled: it divides by something that "
                "is zero, or its numbers are beyond double precision. Check the denominators "
                "and the powers."
            )
            return
        if q == "eom":
            self._eom(verdict)
            return
        if self.same(self.given, self.expected):
            self._settle(verdict, self.given - self.expected)
            return
        if q in ("V", "L") and self._constant(self.given - self.expected):
            self._settle(verdict, self.given - self.expected, constant=True)
            return
        if q == "L" and self._time_only(self.given - self.expected, fb):
            return
        if q == "L" and self._total_derivative(self.given - self.expected, fb):
            return
        if q == "Q" and self._conservative_part(fb):
            return
        if q in ("V", "L") and self._shifted_datum(fb):
            return
        if q == "accel" and self._unsolved(fb):
            return
        self._diagnose(self.given, self.expected, fb)

    def _unsolved(self, fb: list[str]) -> bool:
        """A q̈_j that still holds an acceleration (ẍ in θ̈ = −(g sin θ + cos θ ẍ)/l): an equation
        of motion rearranged, not yet solved for the accelerations, which are found together.
        Compared term by term with the derived q̈_j, its terms read as 'extra', right or wrong
        alike; read as the equation q̈_j = answer, it is judged as one: right but unsolved, or
        wrong where the equation is (a sign error named as such)."""
        m, j = self.m, self.j
        inside = [a for a in m.qdd if self.given.has(a)]
        if not inside:
            return False
        own = m.qdd[j]
        others = [a for a in inside if a != own]
        named = " and ".join(inline(a) for a in others)
        equation = f"${to_latex(own)} = {to_latex(self.given)}$"
        sources = " and ".join(inline(q) for q, a in zip(m.q, m.qdd, strict=True) if a in others)
        if others:
            why = (
                f"Your {inline(own)} still contains {named}, which is itself unknown: the "
                "accelerations are coupled, and are found only by solving the equations of "
                f"motion of all the coordinates together. Eliminate {named} with "
                f"the equation{'s' * (len(others) > 1)} of motion for {sources}, so that the "
                "answer depends only on the coordinates, their rates and t."
            )
        else:
            why = (
                f"Your {inline(own)} contains {inline(own)} itself: solve the equation for it, "
                "so that the answer depends only on the coordinates, their rates and t."
            )
        solved = dict(zip(m.qdd, self.d.solved_accelerations, strict=True))
        reading = own - self.given
        if zero_proof(reading, m) is True:
            fb.append(f"{why} As an equation, {equation} is 0 = 0: it determines nothing.")
            return True
        if not reading.has(own):  # θ̈ = θ̈ + 1: its own acceleration cancels, no equation for it
            fb.append(why)
            return True
        if zero_proof(reading.xreplace(solved), m) is True:
            fb.append(
                f"{why} As an equation, {equation} is right: it holds along the motion (the "
                "equations of motion rearranged), but it is not yet solved."
            )
            return True
        judge = _Judge(self.d, "eom", j, expected_quantity(self.d, "eom", j), reading)
        verdict = Verdict(False)
        judge.run(verdict)
        lines = [line for line in verdict.feedback if not line.startswith("Correct")]
        if not verdict.confirmed or verdict.correct or not lines:
            fb.append(why)  # nothing certain to add about the equation itself
            return True
        fb.append(f"{why} Read as the equation {equation}, it is not right either:")
        fb += lines
        return True

    def _conservative_part(self, fb: list[str]) -> bool:
        """A Q_j that is Q_j^NC plus −∂V/∂q_j: the notes' eq. 31 sums every force, gravity and
        springs included, but the forces step asks only for the non-conservative part (the
        rest is in V). Saying 'Extra term' would hide that the student's physics is right;
        it is still not the quantity asked for. Proved, not sampled. When the answer holds that
        part and something else wrong besides (−k (x − L0) for −k x), the part is named so and
        the rest of the answer is judged on its own: 'Extra term −kx' alone would hide the why.
        """
        q = self.m.q[self.j]
        force = -partial(self.d.work.V, q, self.m)
        if force == 0:
            return False
        # −∂V/∂q, or +∂V/∂q: the same part with the force's sign lost (−g (m₁ − m₂) for the
        # Atwood machine's g (m₁ − m₂)), as common and as much not asked for
        for conservative in (force, -force):
            rest = self.given - self.expected - conservative
            whole = self.same(rest, sp.S.Zero)
            if whole and zero_proof(rest, self.m) is not True:
                continue
            if not whole and not self._holds_terms(self.given - self.expected, conservative):
                continue
            break
        else:
            return False
        flipped = conservative != force
        spec = self.m.spec
        sources = [w for w, has in (("gravity", spec.gravity), ("springs", spec.springs)) if has]
        name = to_latex(q)
        shown = inline(_tidy(conservative, self.m))[1:-1]
        ending = "."
        if whole and self.expected != 0:
            ending = "; without that part your answer would be right."
        elif not whole:
            ending = "; without that part, your answer still differs:"
        origin = "/".join(sources) or "gravity/springs"
        fb.append(
            f"Your answer includes $+\\partial V/\\partial {name} = {shown}$: the conservative "
            f"part ({origin}) with its sign flipped (the force is $-\\partial V/\\partial "
            f"{name}$), and that part is already in V: only the non-conservative part "
            f"$Q_{{{name}}}^{{NC}}$ is asked for" + ending
            if flipped
            else f"Your answer includes the conservative part $-\\partial V/\\partial {name} = "
            f"{shown}$ ({origin}), which is already in V: only "
            f"the non-conservative part $Q_{{{name}}}^{{NC}}$ is asked for" + ending
        )
        if not whole:
            self._diagnose(self.given - conservative, self.expected, fb)
        return True

    def _holds_terms(self, expr: sp.Expr, part: sp.Expr) -> bool:
        """Does ``expr`` hold every term of ``part`` as written: each canonical monomial of
        ``part`` is in ``expr`` with that coefficient, or with it as one of its summands
        (−k x + 7 x is (7 − k) x, and holds −k x)?"""
        whole, piece = self._canonical(expr), self._canonical(part)
        if not piece or len(whole) + len(piece) > MAX_TERMS:
            return False
        for mono, coeff in piece.items():
            if mono not in whole:
                return False
            summands = set(sp.Add.make_args(sp.expand(whole[mono])))
            if not set(sp.Add.make_args(sp.expand(coeff))) <= summands:
                return False
        return True

    def _shifted_datum(self, fb: list[str]) -> bool:
        """A spring's V written k (x − L0)²/2 (the notes' eq. 27, stretch = length − rest
        length) in a scene whose x is already measured from the rest length (the block at
        L0 + x): the 'Extra term −L0 k x' it gives is true but hides why. Said when the answer
        with x − L0 put back to x is the derived one (up to a constant, for V and L)."""
        spec = self.m.spec
        rests = {s.rest_length for s in spec.springs if isinstance(s.rest_length, str)}
        for name, q in zip(self.m.coordinate_names, self.m.q, strict=True):
            for rest in sorted(rests):
                length = self.m.params.get(rest)
                where = self._measured_from(name, rest)
                if length is None or not where:
                    continue
                shifted = self.given.xreplace({q: q + length})
                if not self._constant(shifted - self.expected):
                    continue
                x, x0 = to_latex(q), to_latex(length)
                fb.append(
                    f"In this scene ${x}$ is measured from the spring's rest length ({where}), "
                    f"so the spring's stretch is ${x}$ itself, not ${x} - {x0}$: your answer is "
                    f"the derived one with ${x} - {x0}$ in place of ${x}$."
                )
                return True
        return False

    def _measured_from(self, coordinate: str, rest: str) -> str:
        """'the block sits at L0 + x': a body whose position the scene writes with both the
        coordinate and the rest length, as the scene's file has it; "" if none does."""
        names = {coordinate, rest}
        for body in self.m.spec.bodies:
            position = body.position
            parts = position if isinstance(position, list) else position.components
            for part in parts:
                if isinstance(part, str) and names <= set(re.findall(r"[A-Za-z_]\w*", part)):
                    shown = to_latex(_parse_position(part, self.m))
                    return f"the {body.name} sits at ${shown}$"
        return ""

    def _time_only(self, diff: sp.Expr, fb: list[str]) -> bool:
        """An L that differs from T − V by a function of t alone (a driven support's
        −m g A sin ωt left out): not T − V as asked, but no equation of motion changes, as for an
        added constant; the feedback says so instead of 'Missing term'. Proved: ∂/∂q and ∂/∂q̇
        of the difference are zero (the samples found it not constant: it changes with t)."""
        if not diff.has(t):
            return False
        to_sym, _ = _symbols_for(self.m)
        plain = diff.xreplace(to_sym)
        for q, qd in zip(self.m.q, self.m.qd, strict=True):
            for sym in (to_sym[q], to_sym[qd]):
                if plain.has(sym) and zero_proof(plain.diff(sym), self.m) is not True:
                    return False
        shown = _tidy(-diff, self.m)
        term = f", {inline(shown)}," if sp.count_ops(shown) <= 30 else ""
        fb.append(
            f"Your L falls short of T − V by a function of t only{term} so no equation of "
            "motion changes (∂/∂q and d/dt ∂/∂q̇ of it are 0, as of an added constant); but L "
            "is T − V itself, and that term belongs in it."
        )
        return True

    def _total_derivative(self, diff: sp.Expr, fb: list[str]) -> bool:
        """An L that differs from T − V by a total time derivative dF/dt of some F(q, t) (the
        rotating frame's m Ω (z ẋ + x ż) = d/dt(m Ω x z)): it gives the same equations of motion,
        yet it is not T − V as asked; blaming its terms one by one would hide that. Proved: the
        Euler–Lagrange expression d/dt ∂/∂q̇_j − ∂/∂q_j of the difference is zero for every j
        (the difference is then linear in q̇, the gradient of its F). F is named when sympy
        finds it quickly, and is checked by differentiating it back."""
        m = self.m
        if diff.has(*m.qdd) or sp.count_ops(diff) > PROOF_OPS:
            return False
        if _expansion_size(diff, MAX_NORMAL_TERMS) > MAX_NORMAL_TERMS:
            return False
        for q, qd in zip(m.q, m.qd, strict=True):
            euler_lagrange = partial(diff, qd, m).diff(t) - partial(diff, q, m)
            if zero_proof(euler_lagrange, m) is not True:
                return False
        potential = self._potential_of(diff)
        named = (
            f", $\\frac{{d}}{{dt}}\\left({to_latex(potential)}\\right)$,"
            if potential is not None and sp.count_ops(potential) <= 30
            else " dF/dt of a function F(q, t),"
        )
        fb.append(
            f"Your L differs from T − V by a total time derivative{named} so it gives the same "
            "equations of motion (adding such a term to L changes none of them); but the L "
            "asked for here is T − V itself, without it."
        )
        return True

    def _potential_of(self, diff: sp.Expr) -> sp.Expr | None:
        """F(q, t) with dF/dt = ``diff`` (already shown to be a total derivative), integrated
        one variable at a time when the pieces are polynomials of low degree in q, t, sin q and
        cos q (where integration is quick); None otherwise, or if dF/dt does not give it back."""
        m = self.m
        to_sym, back = _symbols_for(m)
        plain = sp.expand(diff.xreplace(to_sym))
        if _max_power(plain) > MAX_INTEGRATED_POWER or plain.has(sp.Abs, sp.sign, sp.exp):
            return None
        q = [to_sym[x] for x in m.q]
        qd = [to_sym[x] for x in m.qd]
        rates = [plain.diff(v) for v in qd]
        rest = sp.expand(plain - sum(r * v for r, v in zip(rates, qd, strict=True)))
        potential = sp.S.Zero
        for x, rate in [*zip(q, rates, strict=True), (t, rest)]:
            piece = sp.expand(rate - potential.diff(x))
            if piece == 0:
                continue
            params = set(m.params.values())
            if any(a.args[0].free_symbols - {*q, t, *params} for a in piece.atoms(sp.sin, sp.cos)):
                return None
            if not piece.is_polynomial(*q, t, *piece.atoms(sp.sin, sp.cos)):
                return None
            potential += sp.integrate(piece, x)
        if potential.has(sp.Integral):
            return None
        potential = _tidy(potential.xreplace(back), m)
        if zero_proof(potential.diff(t) - diff, m) is not True:
            return None
        return potential

    def _settle(self, verdict: Verdict, diff: sp.Expr, constant: bool = False) -> None:
        """The samples found no difference (or a constant one): "Correct" only on a proof.

        Samples can always be fooled (a bump exp(−10⁶ θ̇²), a 10⁻³⁰ θ is zero at all of them),
        so a difference shown non-zero is diagnosed as the error it is, and one sympy can neither
        show zero nor non-zero is reported as not confirmed: correct stays false."""
        fb = verdict.feedback
        proof = constant_proof(diff, self.m) if constant else zero_proof(diff, self.m)
        if proof is False and not constant and self._tiny_difference(diff, fb):
            return
        if proof is False or (
            proof is None
            and not constant
            and not self._same_to_precision(self.given, self.expected)
        ):
            self._diagnose(self.given, self.expected, fb)
            return
        if proof is None:
            fb.append(
                self._near_miss()
                or self._apart_elsewhere(diff, constant=constant)
                or self._unconfirmed(diff, constant)
            )
            return
        undefined = self._undefined_at_parameters(self.given)
        if undefined:
            fb.append(undefined)
            return
        datum = constant and zero_proof(diff, self.m) is not True
        wrong_units = self._units(self.given) if datum else []
        if wrong_units:  # + m on V is no datum: kg is not an energy (T + m is refused alike)
            fb.append(
                f"Your {self.quantity} differs from the derived one by a constant, which would "
                "only move the datum, but that constant must be an energy like the rest of "
                f"{self.quantity}:"
            )
            fb += wrong_units
            return
        verdict.correct = True
        fb.append(
            "Correct up to a constant: that only moves the datum of V, which changes no "
            "equation of motion."
            if constant and zero_proof(diff, self.m) is not True
            else "Correct."
        )

    def _tiny_difference(self, diff: sp.Expr, fb: list[str]) -> bool:
        """A difference the samples could not see but a proof did, named whole when the term by
        term comparison would not put it as extra terms: a θ̈ written over another denominator
        compares term by term as 'missing' what is only written differently."""
        if self._proportional(diff, self.expected):
            return False  # a factor a hair from 1 (1 + 1e-12): _diagnose says so
        terms = self._terms(self.given, self.expected)
        if terms and all(line.startswith("Extra term") for line in terms):
            return False  # _diagnose names them, with their units
        small = (
            sp.count_ops(diff) <= PROOF_OPS
            and _expansion_size(diff, MAX_NORMAL_TERMS) <= MAX_NORMAL_TERMS
        )
        shown = _tidy(diff, self.m) if small else None
        named = f" by {inline(shown)}" if shown is not None and sp.count_ops(shown) <= 30 else ""
        fb.append(
            f"Your answer differs from the derived result{named}: a difference too small to "
            "show at the states sampled, but sympy shows it is not zero."
        )
        fb += self._units(self.given)
        return True

    def _proportional(self, a: sp.Expr, b: sp.Expr) -> bool:
        """Is a/b one number at every sample, however small (10⁻¹² of b is a factor 1 + 10⁻¹²)?"""
        ratios = [
            x / y
            for x, y in zip(self.values(a), self.values(b), strict=True)
            if abs(y) > 0 and cmath.isfinite(x / y)
        ]
        return bool(ratios) and all(abs(r - ratios[0]) <= 1e-6 * abs(ratios[0]) for r in ratios)

    def _unconfirmed(self, diff: sp.Expr, constant: bool = False, claim: str = "") -> str:
        """Why an answer the samples cannot fault is still not marked correct."""
        # an equation's difference is taken at one set of parameters' scale: not worth showing
        small = sp.count_ops(diff) <= PROOF_OPS and _expansion_size(diff, MAX_TERMS) <= MAX_TERMS
        shown = _tidy(diff, self.m) if not claim and small else None
        named = (
            f"the difference, {inline(shown)},"
            if shown is not None and sp.count_ops(shown) <= 30
            else "the difference"
        )
        what = claim or (
            "differs from the derived result by a constant"
            if constant
            else "equals the derived result"
        )
        return (
            f"{UNCONFIRMED}: your answer {what} at every state sampled, but sympy could not "
            f"show that {named} is {'a constant' if constant else 'zero'}. Samples can miss "
            "a term that is really there (a narrow bump, a tiny coefficient), so check it by "
            "hand, or write your answer more simply (expanded, with sin and cos, without abs, "
            "exp or sqrt it does not need)."
        )

    def _same_to_precision(self, given: sp.Expr, expected: sp.Expr) -> bool:
        """An equality sympy could not prove, held to the precision of the evaluation (25
        digits) relative to the size of the terms, not to TOLERANCE with a floor of 1: that
        floor calls 1e-10·cos φ equal to a Q of 0, and in SI units (G = 6.7e-11) whole terms
        are that small."""
        terms = [*sp.Add.make_args(given), *sp.Add.make_args(expected)][: 2 * MAX_TERMS]
        sizes = [0.0] * len(self.states)
        for term in terms:
            for i, v in enumerate(self.values(term)):
                if not cmath.isnan(v):
                    sizes[i] = max(sizes[i], abs(v))
        for x, y, size in zip(self.values(given), self.values(expected), sizes, strict=True):
            if cmath.isnan(x) or cmath.isnan(y):
                continue
            if abs(x - y) > 1e-15 * size:
                return False
        return True

    def _multiple_of_own(self, given: sp.Expr, expected: sp.Expr) -> bool:
        """Does ``given`` vanish wherever this coordinate's own equation does, whatever the
        other accelerations are? Then it is that equation times a factor (cos θ · (θ̈ + …)),
        not a mix of several coordinates' equations."""
        qdd = self.m.qdd[self.j]
        coefficient = partial(expected, qdd, self.m)
        if coefficient == 0:
            return False
        own = -(expected - coefficient * qdd) / coefficient  # q̈_j from its own equation
        values = self.values(given.xreplace({qdd: own}), motion_only=True)
        scale = [abs(v) for v in self.values(given, motion_only=True)]
        return all(
            not cmath.isnan(v) and abs(v) <= 1e-7 * max(1.0, s)
            for v, s in zip(values, scale, strict=True)
        )

    def _apart_elsewhere(
        self,
        diff: sp.Expr,
        constant: bool = False,
        motion_only: bool = False,
        claim: str = "",
    ) -> str:
        """An equality (or a constant difference) sympy could not prove, tested again across the
        coordinates' whole range: the judging states keep every coordinate in [0.2, 1.3], where
        sin, cos and q are positive, so abs(cos θ)/cos θ or sqrt(θ²) would pass there and be
        wrong at θ = −1 or θ = 2 (the pendulum's own start). A sentence naming a state where
        they part, or "" when none does."""
        if constant and _tidy(diff, self.m).is_number:
            return ""
        rng = random.Random(1)
        positive = set(self.m.spec.positive_coordinates)
        wide = []
        for state in self.motion_states if constant or motion_only else self.states:
            state = dict(state)
            for name, q in zip(self.m.coordinate_names, self.m.q, strict=True):
                state[q] = sp.Float(rng.uniform(0.2 if name in positive else -3.1, 3.1), 30)
            if self._inside(state):  # past a stop no run goes: nothing to claim there
                wide.append(state)
        values = self._values_at(diff, wide)
        base = self._values_at(diff, self.motion_states[:1])[0] if constant else 0
        for state, v in zip(wide, values, strict=True):
            if cmath.isnan(v) or cmath.isnan(base):
                continue  # a pole of either: no number to compare there
            if abs(v - base) > TOLERANCE * max(1.0, abs(base), abs(self._size(state))):
                where = ", ".join(
                    f"{name} = {float(state[q]):.3g}"
                    for name, q in zip(self.m.coordinate_names, self.m.q, strict=True)
                )
                what = claim or (
                    "differs by a constant from the derived result"
                    if constant
                    else "equals the derived result"
                )
                return (
                    f"Your answer {what} where the coordinates are between "
                    f"0.2 and 1.3, but not at {where}: something in it (an abs(), a sign() or a "
                    "sqrt(x**2)?) agrees only on part of the range."
                )
        return ""

    def _size(self, state: dict) -> complex:
        """The expected value at a state, the scale a difference there is measured against."""
        (v,) = self._values_at(self.expected, [state])
        return 0 if cmath.isnan(v) else v

    def _constant(self, diff: sp.Expr) -> bool:
        vals = self.values(diff, motion_only=True)
        return all(abs(v - vals[0]) <= TOLERANCE * max(1.0, abs(vals[0])) for v in vals)

    def _ratio(self, a: sp.Expr, b: sp.Expr, motion_only: bool = False) -> sp.Expr | None:
        """a/b when it is the same number at every state (of the motion only, if asked)."""
        va, vb = self.values(a, motion_only), self.values(b, motion_only)
        ratios = [x / y for x, y in zip(va, vb, strict=True) if abs(y) > 1e-12]
        if len(ratios) < len(va) // 2 or not all(cmath.isfinite(r) for r in ratios):
            return None  # no number at most states (overflow, 0/0): no factor to speak of
        if any(abs(r - ratios[0]) > 1e-8 * max(1, abs(ratios[0])) for r in ratios):
            return None
        return sp.nsimplify(round(ratios[0].real, 10), rational=True)

    def _eom(self, verdict: Verdict) -> None:
        fb = verdict.feedback
        given, expected = self.given, self.expected
        if given == 0 or (
            not any(given.has(a) for a in self.m.qdd) and zero_proof(given, self.m) is True
        ):
            fb.append(
                "Your equation reduces to 0 = 0 (an identity): its terms cancel, so it holds "
                "for every motion and determines nothing. An equation of motion must keep "
                f"{inline(self.m.qdd[self.j])}."
            )
            return
        if not any(given.has(a) for a in self.m.qdd):
            typed = any((given + self.moved).has(a) or self.moved.has(a) for a in self.m.qdd)
            fb.append(
                "The accelerations in your equation cancel between its two sides: what is left "
                f"has no {inline(self.m.qdd[self.j])}, and an equation of motion must keep one."
                if typed
                else "An equation of motion must contain an acceleration "
                f"({inline(self.m.qdd[self.j])}); yours has none."
            )
            self._diagnose(given, expected, fb)
            return
        ratio = self._ratio(given, expected, motion_only=True)
        proof = self._multiple_proof(given, expected) if ratio not in (None, 0) else False
        if proof is None:
            claim = "is the derived equation, scaled,"
            fb.append(
                self._near_miss()
                or self._apart_elsewhere(given - ratio * expected, motion_only=True, claim=claim)
                or self._unconfirmed(given - ratio * expected, claim=claim)
            )
            return
        degenerate = self._degenerate_factor(given, expected) if proof else ""
        if degenerate:
            fb.append(degenerate)
            return
        if proof:
            verdict.correct = True
            exact = self._ratio(given, expected) == 1
            fb.append(
                "Correct."
                if exact
                else "Correct: a non-zero multiple of the derived "
                "equation (the same equation, rearranged or scaled)."
            )
            return
        factor = self._nonvanishing_multiple(given, expected) if ratio in (None, 0) else None
        if factor is not None:
            verdict.correct = True
            fb.append(
                f"Correct: the derived equation multiplied by {inline(factor)}, which changes "
                "with the state but is never zero (nor infinite) where the scene moves, so it "
                "has the same solutions."
            )
            return
        if ratio in (None, 0):  # else the samples saw a multiple, and a proof refuted it
            self._how_it_holds(given, expected, fb)
            if fb:
                return
        if sign_in_group(self, expected, fb) or self._inertia_only(given, expected, fb):
            return
        scale = self._scaling(given, expected)
        if scale is None:  # r φ̈ for m r² φ̈: no term in common, the q̈ terms still say the factor
            scale = self._lead_ratio(given, expected)
        constant = scale is not None and scale != 1 and _never_zero(scale)
        state = scale is not None and scale.has(t) and _sign_definite(scale, self.m)
        if constant or state:
            # compare with the derived equation as the student scaled it, so the feedback names
            # their own terms (g/l sin θ), not the derived equation's (m g l sin θ); a factor of
            # the state that never vanishes (1/(m r), r > 0) changes nothing either
            why = (
                "scaling an equation changes nothing"
                if constant
                else "a factor that is never zero where the scene moves changes nothing"
            )
            fb.append(
                f"Read as the derived equation multiplied by {inline(scale)} ({why}); against that:"
            )
            expected = expected * scale
            self.scale = scale
        self.reference = expected
        self._diagnose(given, expected, fb)

    def _inertia_only(self, given: sp.Expr, expected: sp.Expr, fb: list[str]) -> bool:
        """An equation whose other terms (the forces) are the derived ones (times a number)
        and whose q̈_j coefficient is not: the error is the inertia ((m₁ − m₂) ẍ for
        (m₁ + m₂) ẍ). Reading it as the derived equation scaled to match the q̈ term would
        blame the forces instead, and by a factor that can vanish (m₁ = m₂)."""
        qdd = self.m.qdd[self.j]
        mine, theirs = partial(given, qdd, self.m), partial(expected, qdd, self.m)
        if theirs == 0 or mine.has(qdd) or theirs.has(qdd):
            return False
        forces = self._ratio(given - mine * qdd, expected - theirs * qdd)
        if forces in (None, 0) or not forces.is_Rational:
            return False
        right = _tidy(forces * theirs * qdd, self.m)
        wrong = _tidy(mine * qdd, self.m)
        if sp.count_ops(right) > 30 or sp.count_ops(wrong) > 30:
            return False
        if self._ratio(mine, theirs) is not None:
            return False  # a q̈ term off by a number fits a scaling: the forces are then off
        how = f"you have {inline(wrong)} where {inline(right)} belongs"
        scaled = "" if forces == 1 else f" (as the derived equation times {inline(forces)})"
        fb.append(
            f"Every other term of your equation is right{scaled}, but the inertia term "
            f"(the {inline(qdd)} term) is not: {how}. Its coefficient is the inertia every "
            "force on the system has to accelerate."
        )
        return True

    def _how_it_holds(self, given: sp.Expr, expected: sp.Expr, fb: list[str]) -> None:
        """An equation that is not a multiple of the derived one, read at the samples: the
        equation of another coordinate, or one that holds along the motion all the same."""
        for k in range(len(self.m.q)):
            other = expected_quantity(self.d, "eom", k)
            if k != self.j and self._ratio(given, other, motion_only=True) not in (None, 0):
                fb.append(
                    f"This is the equation of motion for {inline(self.m.q[k])}, not the one for "
                    f"{inline(self.m.q[self.j])}."
                )
                return
        solved = dict(zip(self.m.qdd, self.d.solved_accelerations, strict=True))
        if self.same(given.xreplace(solved), sp.S.Zero) and self._multiple_of_own(given, expected):
            qdd = self.m.qdd[self.j]
            factor = partial(given, qdd, self.m) / partial(expected, qdd, self.m)
            short = sp.count_ops(factor) <= SIMPLIFY_OPS  # named only while it reads at a glance
            by = inline(sp.factor(factor)) if short else "a factor"
            fb.append(
                "Your equation holds along the motion, but it is the derived equation for "
                f"{inline(self.m.q[self.j])} multiplied by {by}, which changes with the state "
                "and may be zero at some states: where it is, your equation says nothing. Scale "
                "an equation of motion only by a non-zero constant, or by a factor that is never "
                "zero."
            )
            return
        if self.same(given.xreplace(solved), sp.S.Zero):
            fb.append(
                "Your equation holds along the motion, but it is not the equation for "
                f"{inline(self.m.q[self.j])}: it mixes in the equations of the other coordinates."
            )
            return

    def _parameter_values(self) -> dict[sp.Symbol, sp.Rational]:
        """The scene's own parameter values, exactly as their decimals read (9.81 is 981/100)."""
        return {
            sym: sp.Rational(str(self.m.spec.parameters[name]))
            for name, sym in self.m.params.items()
        }

    def _at_parameters(self, names: set[sp.Symbol]) -> str:
        """'m = 1, l = 1': the scene's values of the parameters named."""
        return ", ".join(
            f"{name} = {self.m.spec.parameters[name]:g}"
            for name, sym in self.m.params.items()
            if sym in names
        )

    def _undefined_at_parameters(self, expr: sp.Expr) -> str:
        """A sentence when ``expr`` has no value at the scene's own parameter values (it divides
        by m − 1 and m = 1): the samples vary the parameters and never land there, yet that is
        where the scene is run. "" when it has one."""
        values = self._parameter_values()
        undefined = (sp.zoo, sp.nan, sp.oo, -sp.oo)
        if not expr.xreplace(values).has(*undefined) or self.expected.xreplace(values).has(
            *undefined
        ):
            return ""  # defined there, or the scene's own result is not (not the answer's doing)
        poles = []
        for factor in sp.Mul.make_args(sp.factor_terms(sp.together(expr))):
            base, exponent = factor.as_base_exp()
            if exponent.is_negative and base.xreplace(values) == 0:
                poles.append(base)
        named = " and ".join(inline(p) for p in poles) or "something"
        used = set().union(*(p.free_symbols for p in poles)) if poles else expr.free_symbols
        return (
            f"Your answer divides by {named}, which is 0 at the scene's values "
            f"({self._at_parameters(used)}): there it has no value at all. It may not divide by "
            "anything that vanishes at the parameters the scene is run with."
        )

    def _degenerate_factor(self, given: sp.Expr, expected: sp.Expr) -> str:
        """A sentence when the student's equation, proved a constant multiple c of the derived
        one, has c = 0 or c = ∞ at the scene's own parameter values (× (m − 1) with m = 1): there
        it says 0 = 0, or nothing, and determines no acceleration (a prediction refuses it for
        the same reason). The samples vary the parameters and never land there. "" otherwise."""
        qdd = self.m.qdd[self.j]
        derived = partial(expected, qdd, self.m)
        factor = partial(given, qdd, self.m) / derived
        values = self._parameter_values()
        # proved free of the motion: any one state's q, q̇, t serve for what may be left
        motion = {k: v for k, v in self.states[0].items() if k not in values.keys()}
        own = derived.xreplace(values).xreplace(motion)
        if own.has(sp.zoo, sp.nan, sp.oo, -sp.oo) or own.is_zero is not False:
            return ""  # the derived equation itself degenerates there: not the answer's doing
        at = factor.xreplace(values).xreplace(motion)
        if not at.has(sp.zoo, sp.nan, sp.oo, -sp.oo) and at.is_zero is not True:
            try:
                size = abs(complex(at.evalf(50)))
            except (TypeError, ValueError, ArithmeticError):
                size = math.nan
            if math.isfinite(size) and size > 1e-30:
                return ""
        zeros, poles = [], []  # each with its power: (l − 1)² is named so, not l − 1
        for form in (factor, sp.factor_terms(sp.together(factor))):  # as written, then factored
            for part in sp.Mul.make_args(form):
                base, exponent = part.as_base_exp()
                if base.is_number or base.xreplace(values).xreplace(motion) != 0:
                    continue
                if exponent.is_negative:
                    poles.append(sp.Pow(base, -exponent))
                else:
                    zeros.append(part)
            if zeros or poles:
                break
        if zeros and poles:
            how = (
                f"multiplied by {', '.join(map(inline, zeros))} and divided by "
                f"{', '.join(map(inline, poles))}, all 0"
            )
            says = "it reads 0/0, no equation at all"
        elif poles:
            how = f"divided by {' and '.join(map(inline, poles))}, which is 0"
            says = "it divides by zero and has no value"
        else:
            zeros = zeros or [factor]
            how = f"multiplied by {' and '.join(map(inline, zeros))}, which is 0"
            says = "it says 0 = 0"
        used = set().union(*(z.free_symbols for z in (*zeros, *poles))) & set(values)
        where = self._at_parameters(used) or self._at_parameters(set(values))
        return (
            f"Your equation is the derived one {how} at the scene's values ({where}): there "
            f"{says}, and determines no {inline(qdd)}. Scale an equation of motion only by a "
            "constant that is non-zero (and finite) at the scene's parameter values."
        )

    def _near_miss(self) -> str:
        """A sentence when the answer is right but for a number a hair from a simple one
        (1.9999999999 for 2, 0.49999999999 for 1/2): with those numbers it is provably right, and
        as typed it is provably (or visibly, at 25 digits) not. Numbers are judged as typed, so
        it is not correct; the student should read which number, and by how much. "" if none."""
        given = self.given
        snapped = {}
        for r in given.atoms(sp.Rational):
            if r.is_Integer or r.q <= NEAR_MISS_DENOMINATOR:
                continue
            simple = r.limit_denominator(NEAR_MISS_DENOMINATOR)
            if simple != 0 and abs(r - simple) <= NEAR_MISS * abs(simple):
                snapped[r] = simple
        if not snapped:
            return ""
        candidate = given.xreplace(snapped)
        if not self._provably_right(candidate) or not self._apart(given, candidate):
            return ""
        pairs = sorted(snapped.items(), key=lambda kv: sp.default_sort_key(kv[0]))[:3]
        which = "; ".join(
            f"{inline(r)} where {inline(s)} would do (they differ by {inline(abs(r - s))})"
            for r, s in pairs
        )
        return (
            f"Your answer is almost, but not exactly, right: it has {which}. With "
            f"{'that number' if len(pairs) == 1 else 'those numbers'} it would be right; numbers "
            "are judged exactly as typed. A number rounded, or typed with a slip?"
        )

    def _provably_right(self, candidate: sp.Expr) -> bool:
        """Would ``candidate`` be marked correct (on a proof, as the quantity asks)?"""
        if self.quantity == "eom":
            return self._multiple_proof(candidate, self.expected) is True
        diff = candidate - self.expected
        if zero_proof(diff, self.m) is True:
            return True
        return self.quantity in ("V", "L") and constant_proof(diff, self.m) is True

    def _apart(self, given: sp.Expr, candidate: sp.Expr) -> bool:
        """Is ``given`` not ``candidate`` (or, for an equation, not a constant multiple of it)?
        Proved, or seen at the 25-digit evaluation far above its rounding."""
        motion = self.quantity == "eom"
        if not motion:
            diff = given - candidate
            if zero_proof(diff, self.m) is False and (
                self.quantity not in ("V", "L") or constant_proof(diff, self.m) is False
            ):
                return True
        a, b = self.values(given, motion), self.values(candidate, motion)
        pairs = [
            (x, y) for x, y in zip(a, b, strict=True) if not (cmath.isnan(x) or cmath.isnan(y))
        ]
        if len(pairs) < 2:
            return False
        if motion or self.quantity in ("V", "L"):  # a constant factor, or a datum: may differ
            if motion:
                ratios = [x / y for x, y in pairs if abs(y) > 0]
                return len(ratios) >= 2 and any(
                    abs(r - ratios[0]) > 1e-18 * abs(ratios[0]) for r in ratios
                )
            gaps = [x - y for x, y in pairs]
            scale = max(max(abs(x), abs(y)) for x, y in pairs)
            return any(abs(g - gaps[0]) > 1e-18 * max(scale, 1e-300) for g in gaps)
        return any(abs(x - y) > 1e-18 * max(abs(x), abs(y)) for x, y in pairs)

    def _multiple_proof(self, given: sp.Expr, expected: sp.Expr) -> bool | None:
        """Is the equation ``given`` the derived one times a constant (of the parameters)? The
        factor can only be the ratio of their q̈_j coefficients, c; proved when given − c·expected
        is zero and c is free of q, q̇, q̈ and t."""
        qdd = self.m.qdd[self.j]
        ce, cg = partial(expected, qdd, self.m), partial(given, qdd, self.m)
        if ce == 0 or cg == 0:
            return None
        same = zero_proof(given * ce - cg * expected, self.m)
        if same is not True:
            return same
        return constant_proof(cg / ce, self.m)

    def _nonvanishing_multiple(self, given: sp.Expr, expected: sp.Expr) -> sp.Expr | None:
        """The factor F when ``given`` is proved F times the derived equation, F a function of
        the state that is provably never zero or infinite there (r φ̈ + 2 ṙ φ̇ is the cone's
        m r² φ̈ + 2 m r ṙ φ̇ over m r, r > 0): the same equation, divided through. None when
        either cannot be proved: a factor that may vanish hides the equation where it does."""
        factor = self._lead_ratio(given, expected)
        if factor is None or zero_proof(given - factor * expected, self.m) is not True:
            return None
        return factor

    def _lead_ratio(self, given: sp.Expr, expected: sp.Expr) -> sp.Expr | None:
        """The ratio of the q̈_j coefficients when it is a factor of the state (not a constant:
        those are `_never_zero`'s) that never vanishes (1/(m r) with r > 0), else None."""
        qdd = self.m.qdd[self.j]
        ce, cg = partial(expected, qdd, self.m), partial(given, qdd, self.m)
        if ce == 0 or cg == 0:
            return None
        if sp.count_ops(cg / ce) > SIMPLIFY_OPS:
            return None  # a factor this long is nothing a student divides an equation by
        factor = sp.factor(_tidy(cg / ce, self.m))
        return factor if factor.has(t) and _sign_definite(factor, self.m) else None

    def _scaling(self, given: sp.Expr, expected: sp.Expr) -> sp.Expr | None:
        """The factor the student's equation carries over the derived one, read from the terms
        both have: that of the q̈ term when it has the same form in both, else the commonest."""
        g, e = self._canonical(given), self._canonical(expected)
        if len(g) + len(e) > MAX_TERMS:
            return None
        ratios = {mono: sp.simplify(g[mono] / e[mono]) for mono in e if mono in g}
        if not ratios:
            return None
        lead = [mono for mono in ratios if mono.has(self.m.qdd[self.j])]
        if lead:
            return ratios[lead[0]]
        values = list(ratios.values())
        return max(values, key=values.count)

    # -- what is wrong ---------------------------------------------------------------------
    def _diagnose(self, given: sp.Expr, expected: sp.Expr, fb: list[str]) -> None:
        near = self._near_miss()
        if near:  # its terms would read as missing and extra, its units as mixed: neither is
            fb.append(near)
            return
        if self.quantity in ("T", "L") and self._rotation(given, expected, fb):
            fb += self._units(given)
            return
        ratio = self._ratio(given, expected)
        # a fixed multiple of the derived result approximates nothing: the approximation is
        # looked for only when there is no one factor (and its proofs cost a second on a q̈)
        dropped = missing_potential(self, given, expected) if ratio in (None, 0) else []
        if dropped or (ratio in (None, 0) and sign_in_group(self, expected, dropped)):
            fb += dropped + self._units(given)  # V left out, not approximated; or a sign slip
            return
        small_angle = ratio in (None, 0) and (
            approximations.small_angle(self, given, expected)
            or approximations.linearised(self, given, expected)
        )
        if small_angle:
            fb.append(small_angle)
            fb += self._units(given)
            return
        if ratio == -1:
            fb.append("Sign error: your answer is the negative of the correct one.")
        elif ratio == 1 and any(
            line.startswith(("Extra term", "Missing term")) for line in self._terms(given, expected)
        ):
            # a term too small to move the ratio (10⁻¹² θ beside ½ m l² θ̇²) is still a term
            fb += self._terms(given, expected)
        elif ratio == 1:  # a factor that rounds to 1 at 10 digits, yet is not exactly 1
            fb.append(
                "Every term is almost, but not exactly, what it should be (a factor that differs "
                "from 1 only past the ninth digit): a number rounded or typed with a slip?"
            )
        elif ratio is not None and ratio != 0:
            fb.append(
                f"Off by a factor of {inline(ratio)}: every term is {inline(ratio)} times what it "
                "should be."
            )
        else:
            paired = self._paired(given)
            terms = self._terms(given, expected) if paired is None else paired
            if not any(line.startswith("Sign error") for line in terms):  # in the typed terms
                terms = sign_of_a_term(self, expected) or terms
            slips = self._slips(given, expected)
            if terms and all(line.startswith("Sign error") for line in terms):
                # (m₂ − m₁) g for (m₁ − m₂) g is the swap and the sign error at once: one story
                slips = [line for line in slips if "are swapped" not in line]
            fb += terms + slips
        fb += self._units(given)
        if not fb:
            fb.append("Not equal to the derived result at the states sampled.")

    def _rotation(self, given: sp.Expr, expected: sp.Expr, fb: list[str]) -> bool:
        """A rigid body's ½ ω·I_G·ω (notes eq. 25) left out, or written with another I, while
        the rest of T is right: the rolling disk's ½ m ẋ² + ½ (m R²)(ẋ/R)² is 4/3 of T, but
        'every term is 4/3 times what it should be' blames ½ m ẋ², which is right. A sum the
        student wrote is judged so; a single term that is a multiple of T stays 'off by a
        factor' (there is no telling which part it meant), unless it is exactly T without the
        rotation (½ m v_G² alone). Proved, not sampled."""
        m = self.m
        several = max(self.typed_terms, len(self._surface(given))) > 1
        for body in m.bodies:
            if body.frame is None:
                continue
            w = body.frame.ang_vel_in(m.N)
            spin = w.dot(w)
            rotation = w.dot(body.inertia.dot(w)) / 2
            if rotation == 0 or spin == 0:
                continue
            rest = given - (expected - rotation)  # what the student has for the rotation
            datum = sp.S.Zero
            if self.quantity == "L":  # a constant in L only moves V's datum: not the rotation's
                at_rest = {x: 0 for x in (*m.q, *m.qd, *m.qdd)}
                datum = rest.xreplace(at_rest)
                if datum.has(sp.zoo, sp.nan) or datum.has(t):
                    continue
                rest -= datum
            c = self._ratio(rest, rotation)
            if c is None or c == 1 or (c != 0 and not several):
                continue
            if zero_proof(rest - c * rotation, m) is not True:
                continue
            moment = _tidy(2 * rotation / spin, m)
            name = body.name
            if c == 0:
                v = m.velocity(name)
                moving = body.mass * v.dot(v) != 0
                there = f"½ m v_G² of the {name} is there, but " if moving else ""
                fb.append(
                    f"{there[0].upper() + there[1:] if there else ''}"
                    f"{'the' if there else 'The'} rotation of the {name} about its centre of "
                    f"mass G, ½ I_G ω² = {self._show(rotation)} (I_G = {inline(moment)}), is "
                    f"missing: a rigid body's T is ½ m v_G² + ½ I_G ω² (eq. 25)."
                )
                return True
            fb.append(
                f"The rotation's ½ I ω² term of the {name} is not right: you have I = "
                f"{self._show(c * moment)} where {inline(moment)} (the {name}'s I about its "
                f"centre of mass) belongs. The rest of your {self.quantity} is right"
                + (" (up to a constant, which only moves V's datum)." if datum != 0 else ".")
            )
            return True
        return False

    def _canonical(self, expr: sp.Expr) -> dict[sp.Expr, sp.Expr]:
        """_canonical_form, once per expression per check (feedback asks for it repeatedly)."""
        memo = self.__dict__.setdefault("_canonical_memo", {})
        if expr not in memo:
            memo[expr] = self._canonical_form(expr)
        return memo[expr]

    def _canonical_form(self, expr: sp.Expr) -> dict[sp.Expr, sp.Expr]:
        """monomial in q, q̇, q̈, trig(q), t -> its coefficient (parameters only).

        An answer whose expansion would run to thousands of terms ((θ + θ̇ + m + 1)³⁰: 5456)
        is not expanded at all: it has no term-by-term story, and expanding it is what a hostile
        answer counts on to hold a worker. It comes back as more than MAX_TERMS placeholders,
        which every caller reads as 'too many terms'."""
        if _expansion_size(expr, 8 * MAX_TERMS) > 8 * MAX_TERMS:
            return {sp.Dummy(f"term{i}"): sp.S.One for i in range(MAX_TERMS + 1)}
        # sin(10¹⁴ θ) expanded is a Chebyshev polynomial of degree 10¹⁴: such a function stays
        # whole, one opaque factor of its monomial
        hidden = {
            f: sp.Dummy("trig")
            for f in expr.atoms(sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)
            if _huge_multiple(f)
        }
        e = sp.expand(sp.expand_trig(sp.expand(expr.xreplace(hidden))))
        e = sp.expand(TR5(e))
        dynamic = set(self.m.q) | set(self.m.qd) | set(self.m.qdd) | {t} | set(hidden.values())
        shown = {v: k for k, v in hidden.items()}
        out: dict[sp.Expr, sp.Expr] = {}
        for term in sp.Add.make_args(e):
            coeff, mono = term.as_independent(*dynamic, as_Add=False)
            mono = mono.xreplace(shown)
            out[mono] = out.get(mono, 0) + coeff
        if len(out) > MAX_TERMS:  # no term-by-term story to tell; simplifying each would take s
            return out
        return {k: v for k, v in out.items() if sp.simplify(v) != 0}

    def _terms(self, given: sp.Expr, expected: sp.Expr) -> list[str]:
        g, e = self._canonical(given), self._canonical(expected)
        if len(g) + len(e) > MAX_TERMS:
            return []
        if any(c.has(sp.zoo, sp.nan, sp.oo, -sp.oo) for c in g.values()):
            return [
                "Your answer divides by zero: one of its denominators is identically zero "
                "(sin²θ + cos²θ − 1, say), so it has no value at all."
            ]
        if self.quantity in ("V", "L"):  # a constant only moves the datum: neither missing
            g, e = {k: v for k, v in g.items() if k != 1}, {k: v for k, v in e.items() if k != 1}
        fb = []
        for velocity in dict.fromkeys([*map(self._velocity, e), *map(self._velocity, g)]):
            mine = {k: v for k, v in g.items() if self._velocity(k) == velocity}
            theirs = {k: v for k, v in e.items() if self._velocity(k) == velocity}
            lines = self._group_terms(velocity, mine, theirs) or self._piece_terms(mine, theirs)
            if lines:
                lines = self._as_typed(velocity, given, expected) or lines
            fb += lines
        return fb

    def _light(self, expr: sp.Expr) -> dict[sp.Expr, sp.Expr]:
        """monomial -> coefficient as the student wrote the functions: products and powers of
        sums multiplied out, but sin²θ and cos(θ₁ − θ₂) kept whole (the canonical form rewrites
        them, and its pieces are terms nobody typed). {} past the size budget."""
        if _expansion_size(expr, 8 * MAX_TERMS) > 8 * MAX_TERMS:
            return {}
        dynamic = (*self.m.q, *self.m.qd, *self.m.qdd, t)
        out: dict[sp.Expr, sp.Expr] = {}
        for term in sp.Add.make_args(sp.expand(expr)):
            coeff, mono = term.as_independent(*dynamic, as_Add=False)
            out[mono] = out.get(mono, 0) + coeff
        return {k: v for k, v in out.items() if sp.simplify(v) != 0}

    def _as_typed(self, velocity: sp.Expr, given: sp.Expr, expected: sp.Expr) -> list[str]:
        """The group's difference in the student's own terms, when the canonical pieces are not
        them: expanding sin²θ into 1 − cos²θ, or cos(θ₁ − θ₂) into cos θ₁ cos θ₂ + sin θ₁ sin θ₂,
        made 'Extra term m g l/2' of a term nobody typed. [] when nothing was rewritten (the
        pieces are the student's terms, and their lines say it as well)."""
        g = {k: c for k, c in self._light(given).items() if self._velocity(k) == velocity}
        e = {
            k: c
            for k, c in self._light(_tidy(expected, self.m, factor_whole=False)).items()
            if self._velocity(k) == velocity
        }
        if not g or len(g) + len(e) > MAX_TERMS:
            return []
        if all(len(self._canonical(k)) <= 1 for k in (*g, *e)):
            return []  # nothing was rewritten: the pieces are the terms
        change = self._smallest_change(g, e)
        if change is None:
            return []  # no short story in the student's terms: the canonical pieces tell it
        fb, extra, missing = [], [], []
        for k, c in change.items():
            mine = g.get(k, sp.S.Zero)
            right = sp.simplify(mine - c)
            if mine == 0:
                missing.append(right * k)
            elif right == 0:
                extra.append(mine * k)
            else:
                fb.append(self._one_for_one(mine * k, right * k))
        if len(extra) == 1 and len(missing) == 1:
            return [*fb, self._one_for_one(extra[0], missing[0])]
        fb += [f"Extra term {self._show(w)}: the correct answer has none like it." for w in extra]
        fb += [f"Missing term {self._show(x)}{self._source(velocity)}." for x in missing]
        return fb

    def _smallest_change(
        self, g: dict[sp.Expr, sp.Expr], e: dict[sp.Expr, sp.Expr]
    ) -> dict[sp.Expr, sp.Expr] | None:
        """The fewest of the student's terms (then of the derived result's) whose coefficients,
        changed, turn the student's group into the derived one: {term: how much too much}.

        The difference is taken in the canonical form, where equal terms cancel however each
        side wrote them (I₃ cos²θ φ̇²/2 is I₃ φ̇²/2 − I₃ sin²θ φ̇²/2 in the derived T of a top), so
        a term that is right is never named; only then is it said in the student's own terms.
        {} when nothing differs; None when no few terms carry the difference."""
        difference = self._canonical(
            sp.Add(*(c * k for k, c in g.items())) - sp.Add(*(c * k for k, c in e.items()))
        )
        if not difference:
            return {}
        candidates = [*g, *(k for k in e if k not in g)]  # the student's terms first
        columns = [self._canonical(k) for k in candidates]
        rows = set(difference).union(*columns)
        tried = 0
        for size in range(1, min(len(candidates), MAX_CHANGED_TERMS) + 1):
            for chosen in itertools.combinations(range(len(candidates)), size):
                tried += 1
                if tried > MAX_CHANGE_TRIES:
                    return None
                unknowns = [sp.Dummy(f"c{i}") for i in chosen]
                equations = [
                    sp.Add(
                        *(u * columns[i].get(r, 0) for u, i in zip(unknowns, chosen, strict=True))
                    )
                    - difference.get(r, 0)
                    for r in rows
                ]
                solutions = sp.linsolve(equations, unknowns)
                if not isinstance(solutions, sp.FiniteSet) or len(solutions) != 1:
                    continue
                (values,) = solutions
                if any(v.free_symbols & set(unknowns) or sp.simplify(v) == 0 for v in values):
                    continue  # not one way to say it, or a term that needs no change
                return {candidates[i]: sp.simplify(v) for i, v in zip(chosen, values, strict=True)}
        return None

    def _one_for_one(self, mine: sp.Expr, theirs: sp.Expr) -> str:
        """One term of the student's against the one the derivation has in its place."""
        ratio = self._fixed_ratio(self.values(mine), self.values(theirs))
        if ratio == -1:
            return f"Sign error in your term {self._show(mine)}: it should be {self._show(theirs)}."
        if ratio is not None:
            return (
                f"Your term {self._show(mine)} is off by a factor of {inline(ratio)}: it should "
                f"be {self._show(theirs)}."
            )
        return f"You have {self._show(mine)} where {self._show(theirs)} belongs."

    def _velocity(self, mono: sp.Expr) -> sp.Expr:
        """The q̇/q̈ part of a canonical monomial: θ̇₁ θ̇₂ of cos θ₁ cos θ₂ θ̇₁ θ̇₂."""
        return mono.as_independent(*self.m.qd, *self.m.qdd, as_Add=False)[1]

    def _group_terms(
        self, velocity: sp.Expr, g: dict[sp.Expr, sp.Expr], e: dict[sp.Expr, sp.Expr]
    ) -> list[str]:
        """The terms with one velocity monomial, named whole when they read as one term.

        The canonical form splits cos(θ₁ − θ₂) into cos θ₁ cos θ₂ + sin θ₁ sin θ₂; a student who
        left out the cross term, or wrote cos(θ₁ + θ₂), should read about the term they wrote,
        l₁ l₂ m₂ cos(θ₁ − θ₂) θ̇₁ θ̇₂, not about its two halves. [] when the group does not
        tidy to a single term (the pieces are then compared one by one)."""
        whole_e = _tidy(sp.Add(*(c * k for k, c in e.items())), self.m)
        whole_g = _tidy(sp.Add(*(c * k for k, c in g.items())), self.m)
        if not e:
            if not g or whole_g.is_Add:
                return []
            written = self._written_as(g)
            return [
                f"Extra term {written or inline(whole_g)}: the correct answer has none like it."
            ]
        if whole_e.is_Add or (len(e) == 1 and len(g) <= 1):
            return []  # one piece each (or a sum): the piece by piece lines say it as well
        if not g:
            return [f"Missing term {inline(whole_e)}{self._source(velocity)}."]
        ratio = self._fixed_ratio(self.values(whole_g), self.values(whole_e))
        if ratio == 1 and all(sp.simplify(g.get(k, 0) - c) == 0 for k, c in e.items()):
            return []
        if ratio == -1:
            return [f"Sign error in the {inline(whole_e)} term."]
        if ratio is not None and ratio != 1:
            return [f"The term {inline(whole_e)} is off by a factor of {inline(ratio)}."]
        if whole_g.is_Add or velocity == 1:
            return []
        wrong = self._functions(whole_g) - self._functions(whole_e)
        right = self._functions(whole_e) - self._functions(whole_g)
        if len(wrong) == 1 and len(right) == 1:  # cos(θ₁ + θ₂) for cos(θ₁ − θ₂): say just that
            (w,), (r,) = wrong, right
            return [
                f"Your {inline(velocity)} term has {inline(w)} where {inline(r)} belongs: it "
                f"should be {inline(whole_e)}."
            ]
        return [
            f"Your {inline(velocity)} term is {inline(whole_g)}; it should be {inline(whole_e)}."
        ]

    def _written_as(self, pieces: dict[sp.Expr, sp.Expr]) -> str:
        """The student's own term whose canonical pieces these are, as typed: e^{−10⁶ (θ − 0.3)²},
        not the e^{600000 θ} e^{−10⁶ θ²}/e^{90000} that expanding it makes. "" if none is."""
        for term in self._surface(self.given):
            if _expansion_size(term, MAX_TERMS) <= MAX_TERMS and self._canonical(term) == pieces:
                return _as_written(term)
        return ""

    @staticmethod
    def _functions(e: sp.Expr) -> set[sp.Expr]:
        return set(e.atoms(sp.sin, sp.cos, sp.tan))

    def _piece_terms(self, g: dict[sp.Expr, sp.Expr], e: dict[sp.Expr, sp.Expr]) -> list[str]:
        """The canonical pieces compared one by one: missing, extra, sign, factor, coefficient."""
        fb = []
        for mono, coeff in e.items():
            term = coeff * mono
            if mono not in g:
                fb.append(f"Missing term {self._show(term)}{self._source(mono)}.")
                continue
            r = sp.simplify(g[mono] / coeff)
            if r == -1:
                fb.append(f"Sign error in the {self._show(term)} term{self._moved(mono)}.")
            elif r.is_number and r != 1:
                fb.append(f"The term {self._show(term)} is off by a factor of {inline(r)}.")
            elif r != 1 and mono == 1:  # no motion to name the term by: the values themselves
                fb.append(self._in_place_of(g[mono], coeff))
            elif r != 1:
                fb.append(
                    f"The term {self._show(term)} has the coefficient "
                    f"{self._show(g[mono])} instead of {self._show(coeff)}."
                )
        for mono, coeff in g.items():
            if mono not in e:
                fb.append(
                    f"Extra term {self._show(coeff * mono)}: the correct answer has none like it."
                )
        return fb

    def _in_place_of(self, mine: sp.Expr, theirs: sp.Expr) -> str:
        """The part free of the motion compared as values ('the term X has the coefficient Y
        instead of X' named the whole answer as its own coefficient). A q̈ of ±g is named for
        what it is: a free fall, the body alone, with the rest of the system left out."""
        gravity = self.m.spec.gravity
        g = self.m.params.get(str(gravity.acceleration)) if gravity else None
        free_fall = g is not None and self.given in (g, -g) and mine == self.given
        if self.quantity == "accel" and free_fall:
            qdd = to_latex(self.m.qdd[self.j])
            return (
                f"Your ${qdd} = {to_latex(self.given)}$ is the free-fall value, as if the body "
                f"fell alone; the correct ${qdd} = {to_latex(_tidy(self.expected, self.m))}$: the "
                "rest of the system is missing (the other bodies' inertia, and the forces they "
                "pass on through the constraints)."
            )
        return f"You have {self._show(mine)} where {self._show(theirs)} belongs."

    def _source(self, mono: sp.Expr) -> str:
        if self.quantity not in ("T", "L"):
            return ""
        from_speeds = [qd for qd in self.m.qd if mono.has(qd)]
        if not from_speeds:
            return ""
        return ": the part that comes from " + " and ".join(inline(v) for v in from_speeds)

    def _surface(self, expr: sp.Expr) -> list[sp.Expr]:
        """The terms as written (cos(θ₁ − θ₂) kept whole), a common factor multiplied in."""
        terms = list(sp.Add.make_args(expr))
        while len(terms) == 1 and isinstance(terms[0], sp.Mul):
            sums = [f for f in terms[0].args if isinstance(f, sp.Add)]
            if len(sums) != 1:
                break
            rest = terms[0] / sums[0]
            terms = [rest * a for a in sums[0].args]
        return terms

    def _paired(self, given: sp.Expr) -> list[str] | None:
        """Feedback term by term as the terms are written, when each term of the answer is a
        fixed multiple of its own term of the derived result (a sign, a factor): names
        'the l₁ l₂ m₂ cos(θ₁ − θ₂) θ̇₁ θ̇₂ term' rather than its expanded pieces. None when the
        terms do not pair up one to one (the canonical comparison then finds what differs)."""
        derived = [
            self.scale * e for e in self._surface(_tidy(self.expected, self.m, factor_whole=False))
        ]
        written = self._surface(given)
        if not 1 < len(derived) <= 12 or len(written) != len(derived):
            return None
        values = {id(e): self.values(e) for e in (*derived, *written)}
        fb, free = [], list(written)
        for e in derived:
            match = next((g for g in free if self._fixed_ratio(values[id(g)], values[id(e)])), None)
            if match is None:
                return None
            free.remove(match)
            ratio = self._fixed_ratio(values[id(match)], values[id(e)])
            if ratio == -1:
                fb.append(f"Sign error in the {self._show(e)} term{self._moved_term(match)}.")
            elif ratio != 1:
                fb.append(f"The term {self._show(e)} is off by a factor of {inline(ratio)}.")
        return fb

    @staticmethod
    def _fixed_ratio(a: list[complex], b: list[complex]) -> sp.Expr | None:
        """a/b when it is one number at every sampled state (parameters varied too)."""
        ratios = [x / y for x, y in zip(a, b, strict=True) if abs(y) > 1e-12]
        if not all(cmath.isfinite(r) for r in ratios):
            return None
        if len(ratios) < len(a) // 2 or any(
            abs(r - ratios[0]) > 1e-8 * max(1, abs(ratios[0])) for r in ratios
        ):
            return None
        return sp.nsimplify(round(ratios[0].real, 10), rational=True) or None

    def _moved_term(self, term: sp.Expr) -> str:
        """A term written right of '=' shows up negated in lhs − rhs."""
        if self.moved == 0 or -term not in sp.Add.make_args(self.moved):
            return ""
        return " (a term carried across '=' changes its sign)"

    def _moved(self, mono: sp.Expr) -> str:
        """Why a term of an equation may have its sign flipped: it was carried across '='."""
        if self.moved == 0 or mono not in self._canonical(self.moved):
            return ""
        return " (a term carried across '=' changes its sign)"

    def _show(self, e: sp.Expr) -> str:
        return inline(_tidy(e, self.m))

    def _slips(self, given: sp.Expr, expected: sp.Expr) -> list[str]:
        """Typical slips: two parameters of the same units swapped, q mixed up with q̇."""
        fb = []
        dims = self._dimensions()
        params = list(self.m.params.values())
        for i, a in enumerate(params):
            for b in params[i + 1 :]:
                if dims and dims.get(a) != dims.get(b):
                    continue
                if (given.has(a) or given.has(b)) and self._slip(
                    given.xreplace({a: b, b: a}), expected
                ):
                    fb.append(
                        f"{inline(a)} and {inline(b)} are swapped: a term belongs to the "
                        "other body."
                    )
        for q, qd in zip(self.m.q, self.m.qd, strict=True):
            swapped = given.xreplace({qd: q}).xreplace({q: qd}) if given.has(qd) else None
            if swapped is None:
                swapped = given.xreplace({q: qd})
            if swapped != given and self._slip(swapped, expected):
                fb.append(f"You mixed up {inline(q)} and {inline(qd)} somewhere.")
        return fb

    def _slip(self, changed: sp.Expr, expected: sp.Expr) -> bool:
        """Is the answer with a slip undone the derived one, to the evaluation's precision (a
        tolerance with a floor of 1 would undo a 'slip' in 1e-10·cos θ against a Q of 0), and
        provably so (exp(−10⁶ (θ − 0.3)²) swapped to θ̇ is 0 at every sample, and no slip)?"""
        return (
            self.same(changed, expected)
            and self._same_to_precision(changed, expected)
            and zero_proof(changed - expected, self.m) is True  # a bump fools samples, see run
        )

    def _dimensions(self) -> dict[sp.Expr, units.Dim]:
        return scene_dimensions(self.m)

    def _quantity_dimension(self, dims: dict[sp.Expr, units.Dim]) -> units.Dim | None:
        """The units of the quantity asked for when its derived value is 0: an energy for T, V
        and L; energy per unit of q_j for Q_j (a torque for an angle), energy·s per unit of q_j
        for p_j; q_j per s² for q̈_j."""
        energy = units.dimension(sp.expand(self.d.work.T), dims)
        j = self.j or 0
        if self.quantity == "accel":
            return dims.get(self.m.qdd[j])
        if energy is None:
            return None
        per = {"Q": self.m.q[j], "momentum": self.m.qd[j]}.get(self.quantity)
        if per is None:
            return energy if self.quantity in ("T", "V", "L") else None
        base = dims[per]
        return (energy[0] - base[0], energy[1] - base[1], energy[2] - base[2])

    def _units(self, given: sp.Expr) -> list[str]:
        dims = self._dimensions()
        if not dims:
            return []
        reference = sp.expand(self.reference)
        if reference == 0:  # "0" has every unit: the quantity's own, from T (Q_θ of a pendulum)
            want = self._quantity_dimension(dims)
        else:
            want = units.dimension(reference, dims)
        if want is None:
            return []
        unit = "a pure number" if want == NO_UNITS else units.fmt(want)
        what = {
            "T": "an energy",
            "V": "an energy",
            "L": "an energy",
            "eom": f"{unit} like the rest of the equation",
            "accel": f"{unit} (an acceleration of {inline(self.m.q[self.j or 0])})",
        }.get(self.quantity, unit)
        # the terms as written (a sum inside a power is one term that mixes units), and a few
        # of them: a hostile (a + b + …)**30 must not become thousands of lines
        wrong = []
        for term in self._surface(given):
            if term == 0:
                continue  # "0" has every unit; a bare number is dimensionless, in V as in T
            have = units.dimension(term, dims)
            if have != want:
                wrong.append((term, have))
        fb = []
        for term, have in wrong[:MAX_UNIT_LINES]:
            if have is None:
                fb.append(
                    f"The term {_as_written(term)} mixes units (e.g. a sum inside a power or "
                    "a dimensional argument to a function)."
                )
            else:
                has = "is a pure number" if have == NO_UNITS else f"has units {units.fmt(have)}"
                fb.append(f"The term {_as_written(term)} {has}, not {what}: it cannot belong here.")
        if len(wrong) > MAX_UNIT_LINES:
            fb.append(f"… and {len(wrong) - MAX_UNIT_LINES} more terms with the wrong units.")
        return fb
