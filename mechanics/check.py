"""Is a student's T, V, L, Q_j, equation of motion, q̈ or p_j right — and if not, where is it wrong?

Equivalence is decided at random states (parameters near their defaults, random q, q̇, q̈, t),
backed by symbolic simplification, so `1 - cos(x)**2` equals `sin(x)**2` however it is written.
A wrong answer is compared term by term with the derived one, after both are brought to one
canonical form (trig of single coordinates, sin² written as 1 − cos²): what is missing, what is
extra, which term has its sign flipped or a wrong factor; then the usual slips are tried (two
parameters swapped, q mixed up with q̇) and the units of every term are checked.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Any

import sympy as sp
from sympy.simplify.fu import TR5

from mechanics import units
from mechanics.answers import to_convention
from mechanics.derive import Derivation
from mechanics.expr import ExprError, parse, to_latex, to_plain
from mechanics.model import T as t
from mechanics.spec import SpecError
from mechanics.steps import tidy

QUANTITIES = ("T", "V", "L", "Q", "eom", "accel", "momentum")
PER_COORDINATE = {"Q", "eom", "accel", "momentum"}
SAMPLES = 12
TOLERANCE = 1e-9


@dataclass
class Verdict:
    correct: bool
    feedback: list[str] = field(default_factory=list)
    answer_latex: str = ""
    expected_latex: str = ""

    def to_json(self, reveal: bool) -> dict[str, Any]:
        out = {
            "correct": self.correct,
            "feedback": self.feedback,
            "answer_latex": self.answer_latex,
        }
        if reveal:
            out["expected_latex"] = self.expected_latex
        return out


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
            raise SpecError(
                [{"field": "coordinate", "message": f"one of {', '.join(model.coordinate_names)}"}]
            )
        j = model.coordinate_names.index(coordinate)
    expected = expected_quantity(d, quantity, j)
    text = to_convention(answer, model.coordinate_names, model.names.keys() | {"t"})
    names = dict(model.names)
    names.update(
        {f"{q}_ddot": qdd for q, qdd in zip(model.coordinate_names, model.qdd, strict=True)}
    )
    if "=" in text:
        if quantity != "eom" or text.count("=") > 1:
            raise ExprError("'=' belongs only in an equation of motion (once)", field="answer")
        lhs, rhs = text.split("=")
        given = parse(lhs, names, field="answer") - parse(rhs, names, field="answer")
    else:
        given = parse(text, names, field="answer")
    verdict = Verdict(False, answer_latex=to_latex(given), expected_latex=_latex(d, quantity, j))
    judge = _Judge(d, quantity, j, expected, given)
    judge.run(verdict)
    return verdict


def _latex(d: Derivation, quantity: str, j: int | None) -> str:
    w, m = d.work, d.model
    if quantity == "eom":
        return f"{to_latex(w.eom_lhs[j])} = {to_latex(w.Q[j])}"
    if quantity == "accel":
        return f"{to_latex(m.qdd[j])} = {to_latex(d.solved_accelerations[j])}"
    return to_latex(expected_quantity(d, quantity, j))


class _Judge:
    def __init__(self, d: Derivation, quantity: str, j: int | None, expected, given) -> None:
        self.d, self.m, self.quantity, self.j = d, d.model, quantity, j
        self.expected, self.given = expected, given
        rng = random.Random(0)
        self.states = [self._state(rng) for _ in range(SAMPLES)]
        # The same motion states at one set of parameters: for "constant" and "multiple of",
        # which may depend on the parameters but not on q, q̇, q̈ or t.
        fixed = {sym: self.states[0][sym] for sym in self.m.params.values()}
        self.motion_states = [{**s, **fixed} for s in self.states]

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
        out = []
        for s in self.motion_states if motion_only else self.states:
            try:
                out.append(complex(expr.xreplace(s).evalf(25)))
            except (TypeError, ValueError):
                out.append(complex("nan"))
        return out

    def same(self, a: sp.Expr, b: sp.Expr) -> bool:
        for x, y in zip(self.values(a), self.values(b), strict=True):
            if not (abs(x - y) <= TOLERANCE * max(1.0, abs(x), abs(y))):
                return False
        return True

    def run(self, verdict: Verdict) -> None:
        q = self.quantity
        fb = verdict.feedback
        if q == "eom":
            self._eom(verdict)
            return
        if self.same(self.given, self.expected):
            verdict.correct = True
            fb.append("Correct." + self._symbolic_note(self.given - self.expected))
            return
        if q in ("V", "L") and self._constant(self.given - self.expected):
            verdict.correct = True
            fb.append(
                "Correct up to a constant: that only moves the datum of V, which changes "
                "no equation of motion."
            )
            return
        self._diagnose(self.given, self.expected, fb)

    def _symbolic_note(self, diff: sp.Expr) -> str:
        if tidy(diff, self.m) == 0:
            return ""
        return " (Equal at every state sampled; sympy could not show it symbolically.)"

    def _constant(self, diff: sp.Expr) -> bool:
        vals = self.values(diff, motion_only=True)
        return all(abs(v - vals[0]) <= TOLERANCE * max(1.0, abs(vals[0])) for v in vals)

    def _ratio(self, a: sp.Expr, b: sp.Expr, motion_only: bool = False) -> sp.Expr | None:
        """a/b when it is the same number at every state (of the motion only, if asked)."""
        va, vb = self.values(a, motion_only), self.values(b, motion_only)
        ratios = [x / y for x, y in zip(va, vb, strict=True) if abs(y) > 1e-12]
        if not ratios or any(abs(r - ratios[0]) > 1e-8 * max(1, abs(ratios[0])) for r in ratios):
            return None
        return sp.nsimplify(round(ratios[0].real, 10), rational=True)

    def _eom(self, verdict: Verdict) -> None:
        fb = verdict.feedback
        given, expected = self.given, self.expected
        if not any(given.has(a) for a in self.m.qdd):
            fb.append("An equation of motion must contain an acceleration (q̈); yours has none.")
            self._diagnose(given, expected, fb)
            return
        if self._ratio(given, expected, motion_only=True) not in (None, 0):
            verdict.correct = True
            exact = self._ratio(given, expected) == 1
            fb.append(
                "Correct."
                if exact
                else "Correct: a non-zero multiple of the derived "
                "equation (the same equation, rearranged or scaled)."
            )
            return
        solved = dict(zip(self.m.qdd, self.d.solved_accelerations, strict=True))
        if self.same(given.xreplace(solved), sp.S.Zero):
            fb.append(
                "Your equation holds along the motion, but it is not the equation for "
                f"{self.m.coordinate_names[self.j]}: it mixes in the equations of the other "
                "coordinates."
            )
            return
        self._diagnose(given, expected, fb)

    # -- what is wrong ---------------------------------------------------------------------
    def _diagnose(self, given: sp.Expr, expected: sp.Expr, fb: list[str]) -> None:
        ratio = self._ratio(given, expected)
        if ratio == -1:
            fb.append("Sign error: your answer is the negative of the correct one.")
        elif ratio is not None and ratio != 0:
            fb.append(f"Off by a factor of {ratio}: every term is {ratio} times what it should be.")
        else:
            fb += self._terms(given, expected)
            fb += self._slips(given, expected)
        fb += self._units(given)
        if not fb:
            fb.append("Not equal to the derived result at the states sampled.")

    def _canonical(self, expr: sp.Expr) -> dict[sp.Expr, sp.Expr]:
        """monomial in q, q̇, q̈, trig(q), t -> its coefficient (parameters only)."""
        e = sp.expand(sp.expand_trig(sp.expand(expr)))
        e = sp.expand(TR5(e))
        dynamic = set(self.m.q) | set(self.m.qd) | set(self.m.qdd) | {t}
        out: dict[sp.Expr, sp.Expr] = {}
        for term in sp.Add.make_args(e):
            coeff, mono = term.as_independent(*dynamic, as_Add=False)
            out[mono] = out.get(mono, 0) + coeff
        return {k: v for k, v in out.items() if sp.simplify(v) != 0}

    def _terms(self, given: sp.Expr, expected: sp.Expr) -> list[str]:
        g, e = self._canonical(given), self._canonical(expected)
        if len(g) + len(e) > 40:
            return []
        fb = []
        for mono, coeff in e.items():
            term = coeff * mono
            if mono not in g:
                fb.append(f"Missing term {self._show(term)}{self._source(mono)}.")
                continue
            r = sp.simplify(g[mono] / coeff)
            if r == -1:
                fb.append(f"The term {self._show(term)} has the wrong sign.")
            elif r.is_number and r != 1:
                fb.append(f"The term {self._show(term)} is off by a factor of {r}.")
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

    def _source(self, mono: sp.Expr) -> str:
        if self.quantity not in ("T", "L"):
            return ""
        from_speeds = [qd for qd in self.m.qd if mono.has(qd)]
        if not from_speeds:
            return ""
        return ": the part that comes from " + " and ".join(to_plain(v) for v in from_speeds)

    def _show(self, e: sp.Expr) -> str:
        return to_plain(tidy(e, self.m))

    def _slips(self, given: sp.Expr, expected: sp.Expr) -> list[str]:
        """Typical slips: two parameters of the same units swapped, q mixed up with q̇."""
        fb = []
        dims = self._dimensions()
        params = list(self.m.params.values())
        for i, a in enumerate(params):
            for b in params[i + 1 :]:
                if dims and dims.get(a) != dims.get(b):
                    continue
                if (given.has(a) or given.has(b)) and self.same(
                    given.xreplace({a: b, b: a}), expected
                ):
                    fb.append(f"{a} and {b} are swapped: a term belongs to the other body.")
        for name, q, qd in zip(self.m.coordinate_names, self.m.q, self.m.qd, strict=True):
            swapped = given.xreplace({qd: q}).xreplace({q: qd}) if given.has(qd) else None
            if swapped is None:
                swapped = given.xreplace({q: qd})
            if self.same(swapped, expected):
                fb.append(f"You mixed up {name} and {name}_dot somewhere.")
        return fb

    def _dimensions(self) -> dict[sp.Expr, units.Dim]:
        m = self.m
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

    def _units(self, given: sp.Expr) -> list[str]:
        dims = self._dimensions()
        if not dims:
            return []
        want = units.dimension(sp.expand(self.expected), dims)
        if want is None:
            return []
        fb = []
        for term in sp.Add.make_args(sp.expand(given)):
            have = units.dimension(term, dims)
            if have is None:
                fb.append(
                    f"The term {to_plain(term)} mixes units (e.g. a sum inside a power or "
                    "a dimensional argument to a function)."
                )
            elif have != want:
                what = "an energy" if want == units.ENERGY else f"{units.fmt(want)}"
                fb.append(
                    f"The term {to_plain(term)} has units {units.fmt(have)}, not {what}: "
                    "it cannot belong here."
                )
        return fb
