"""Equilibrium by virtual work (notes II.A), stability, and small oscillations about it.

At rest every q̇ and q̈ vanish, and the equations of motion reduce to f_j(q, 0, t) = 0: for a
scleronomic system that is δW = Σ_j (Q_j^NC − ∂V/∂q_j) δq_j = 0 for arbitrary δq_j; where frames
turn at a prescribed rate it also keeps the centrifugal terms, which is what "equilibrium in the
rotating frame" means (the bead on a spinning hoop).

Roots are found twice, so that none is silently missed or invented: sympy's closed forms (with the
conditions under which they exist), each checked by plugging it back in, and always a bounded
numeric search (Newton from a capped set of starts), whose roots are matched to the closed forms or
added. A coordinate is an angle, wrapped into (−π, π], when the equations are 2π-periodic in it (it
enters only through sin/cos of itself), whatever its declared units say.

Linearizing about each gives M δq̈ + C δq̇ + K δq = 0 (C: damping and the gyroscopic terms,
Coriolis where a frame turns or forces that do no work, a magnetic one). Stability and frequencies
come from the eigenvalues of the first-order system, not from K alone: a turntable's Coriolis
terms split and can even restore frequencies K alone gets wrong. 'Stable by the potential' also
needs the velocity-dependent forces to do no positive work, which no linearization sees (c ẋ³);
and a K that is not symmetric (a follower load) has no potential behind it at all.

The module is past the house's ~400 lines because the root search, its checks and the stability
verdict are one procedure whose parts only make sense together.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import math
import re
import time
import unicodedata
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp
from sympy.physics.vector import Vector

from mechanics import equilibrium_branches as branches
from mechanics import equilibrium_closed_form as closed_form
from mechanics import equilibrium_families as families_
from mechanics import equilibrium_flat as flat
from mechanics import equilibrium_stability as stability
from mechanics.degenerate import check_mass_matrix
from mechanics.derive import Derivation
from mechanics.equilibrium_branches import Variant
from mechanics.expr import parse, to_latex, to_plain
from mechanics.model import T as t
from mechanics.model import _inertia_errors
from mechanics.numeric import overflow_error
from mechanics.spec import SpecError
from mechanics.steps import Line, Step, tidy
from mechanics.steps.conserved import explicit_time, vanishes
from mechanics.steps.energy import letter

SYMBOLIC_OPS_LIMIT = 200
TOL = 1e-9
#: The numeric search's bounds: a posted spec may be anything, the search must still end.
MAX_STARTS = 256
MAX_NEWTON_STEPS = 60
SEARCH_SECONDS = 3.0
MAX_EQUILIBRIA = 24

KINDS = ("stable", "asymptotically stable", "gyroscopically stable", "marginal", "unstable")
STABLE_KINDS = frozenset(KINDS[:3])
_TRIG = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)


@dataclass
class Root:
    """One equilibrium: values by coordinate index, closed forms where known, and its origin."""

    numeric: dict[int, float]
    symbolic: dict[int, sp.Expr] = field(default_factory=dict)
    exists: str = "always"
    how: str = "closed form"
    #: The same conditions as ``exists``, in LaTeX for the page (empty when always).
    exists_latex: str = ""
    #: How many independent directions of equilibria pass through it (a family), and in words.
    family_dim: int = 0
    family: str = ""


@dataclass
class Verdict:
    """What the eigenvalues of the linearization say, and why, in words."""

    kind: str
    reason: str
    eigenvalues: list[complex]
    frequencies: list[float]
    modes: list[list[float]]
    phases: list[list[float]]
    linear: dict | None
    #: Each eigenvalue's eigenvector, its displacement half (δq in the coordinates kept).
    vectors: list[np.ndarray] = field(default_factory=list)
    #: The family of equilibria it belongs to, in words (empty: an isolated point).
    family: str = ""
    #: q0 is a pole of the coordinates: they cannot move in every direction there.
    pole: bool = False
    #: Directions of a family of equilibria through q0 that the higher-order test found.
    family_dim: int = 0

    @property
    def stable(self) -> bool:
        return self.kind in STABLE_KINDS


def _once(d: Derivation, what: str, key: Any, compute: Callable[[], Any]) -> Any:
    """The symbolic work that does not depend on the parameter values, done once per derivation:
    a slider move asks again with new numbers only, and sympy's share of an answer is then a
    numeric evaluation of what was derived the first time."""
    memo = d.__dict__.setdefault("_equilibria_memo", {})
    if (what, key) not in memo:
        memo[(what, key)] = compute()
    return memo[(what, key)]


def equilibria(d: Derivation, parameters: dict[str, float] | None = None) -> dict[str, Any]:
    """Steps in the notes' order and every equilibrium at the given parameter values."""
    m = d.model
    values = {m.params[k]: sp.Float(v) for k, v in _checked(d, parameters or {}).items()}
    general = _once(
        d, "at rest", "", lambda: _at_rest(Variant(m, d.work.mass_matrix, d.work.forcing, []))
    )
    steps = [_virtual_work_step(d, general)]
    warnings: list[str] = []
    # Parameters that are 0 here are set to 0 exactly before anything is evaluated: the general
    # forces can hold 0/0 that cancels then (a spring's k (ℓ − ℓ₀) d/ℓ with ℓ₀ = 0 at its anchor)
    # and 0·∞ (k ℓ₀/ℓ with k = 0): numbers alone called the anchor 'no equilibrium'.
    zeros = tuple(sorted((p for p, x in values.items() if float(x) == 0), key=str))
    base = _once(d, "zeroed", zeros, lambda: _zeroed(d, zeros))
    conditions = _once(d, "at rest", zeros, lambda: _at_rest(base)) if zeros else general
    conditions = [_drop_idle_drive(d, c, values) for c in conditions]
    if any(explicit_time(c, m) for c in conditions):
        # a hoop spun about a horizontal diameter has no amplitude to set to 0
        warnings.append(
            "The forces at rest depend on time (a frame turning at a prescribed rate carries "
            "gravity round in it): there is no fixed equilibrium."
            if _frame_turns(m)
            else "The forces at rest depend on time (a drive): there is no fixed "
            "equilibrium. Set the drive amplitude to 0 to find the undriven ones."
        )
        return {"steps": [s.to_json() for s in steps], "equilibria": [], "warnings": warnings}
    periods = _once(d, "periods", "", lambda: _periods(d))
    found: list[tuple[Derivation, Root]] = []
    everywhere = Variant(m, d.work.mass_matrix, d.work.forcing, [])
    if len(_once(d, "variants", (), lambda: branches.variants(m, everywhere, ()))[0]) > 1:
        # the step shows every side's conditions as derived, whatever is 0 at these values, in
        # place of the general ones (which are the first side's, shown twice with and without
        # its label)
        del steps[0].lines[-len(m.q) :]
        for variant in _once(d, "variants", (), lambda: branches.variants(m, everywhere, ()))[0]:
            conds = _once(d, "at rest", ((), variant.label), functools.partial(_at_rest, variant))
            steps[0].lines += _condition_lines(d, conds, f" ({variant.label})")
    variants, notes = _once(d, "variants", zeros, lambda: branches.variants(m, base, zeros))
    warnings += notes
    idle = _idle_at(m, [_drop_idle_drive(d, c, values) for c in general], values)
    families: list[str] = []
    inside = _inside_values(m, idle)
    if idle:
        families.append(_idle_note(m, idle, len(idle) == len(m.q), inside))
    numeric_only: dict[str, list[Root]] = {}  # why sympy gave no closed form → roots searched
    for variant in variants:
        if variant.label and len(variants) > 1:
            key = (zeros, variant.label)
            conds = _once(d, "at rest", key, functools.partial(_at_rest, variant))
        else:
            conds = conditions
        conds = [_drop_idle_drive(d, c, values) for c in conds]
        conds = [sp.S.Zero if j in idle else c for j, c in enumerate(conds)]
        try:
            roots, notes, why = _equilibrium_points(variant, conds, values, periods)
        except _ConditionsOverflow as exc:
            raise _beyond_doubles(d, parameters or {}, exc.q0, exc) from None
        for note in notes:
            if note not in warnings:
                warnings.append(note)
        searched = numeric_only.setdefault(why, []) if why is not None else []
        for root in roots:
            if not any(_same(root.numeric, r.numeric, periods) for _, r in found):
                found.append((variant, root))
                searched.append(root)
    # one sentence per reason, over every side of the springs' anchors
    warnings += [_numeric_note(why, roots) for why, roots in numeric_only.items()]
    found.sort(key=lambda vr: [abs(vr[1].numeric.get(j, 0.0)) for j in range(len(m.q))])
    crowded = families_.crowded([r.numeric for _, r in found], periods)
    free = sorted({j for j, c in enumerate(conditions) if c == 0} | set(idle))
    results, verdicts = [], []
    left_out = False  # balanced where the system has no state: "never balance" would be false
    continua = families_.Continua(m, values)
    for variant, root in found:
        q0 = [root.numeric.get(j, inside.get(j, 0.0)) for j in range(len(m.q))]
        if continua.member(q0) or len(results) > MAX_EQUILIBRIA:
            continue  # a family's member is said once; past the list's length, not judged
        where = _undefined_position(m, q0, values)
        if where is not None:
            warnings.append(
                f"The forces balance at {_point_text(m, q0)}, but the position of {where} is "
                "not defined there (its function leaves its domain, e.g. a root or a "
                "logarithm of a negative number): the system has no such state, so it is "
                "left out."
            )
            left_out = True
            continue
        unphysical = _unphysical_inertia(m, variant.mass_matrix, q0, values)
        if unphysical is not None:
            warnings.append(
                f"The forces balance at {_point_text(m, q0)}, but {unphysical}, so the point "
                "is left out."
            )
            left_out = True
            continue
        try:
            with np.errstate(all="ignore"):
                power = _power_at(d, values, q0)
                verdict = _stability(variant, q0, free, values, root.family_dim, power)
        except (_BeyondDoubles, np.linalg.LinAlgError, OverflowError) as exc:
            raise _beyond_doubles(d, parameters or {}, q0, exc) from None
        except _NotSmooth as exc:
            if exc.in_position:
                verdict = _kink_verdict(d, variant, q0, values, power)
                if _KINK_WARNING not in warnings:
                    warnings.append(_KINK_WARNING)
            else:
                verdict = Verdict("marginal", _NOT_SMOOTH, [], [], [], [], None)
                if _NOT_SMOOTH_WARNING not in warnings:
                    warnings.append(_NOT_SMOOTH_WARNING)
        except ValueError as exc:  # sympy cannot differentiate the forces: sign(q̇) at q̇ = 0
            if not _dry_friction(d):  # no friction to blame (g = 1e308 overflows): say so
                raise _beyond_doubles(d, parameters or {}, q0, exc) from None
            verdict = Verdict("marginal", _NOT_SMOOTH, [], [], [], [], None)
            if _NOT_SMOOTH_WARNING not in warnings:
                warnings.append(_NOT_SMOOTH_WARNING)
        except (ZeroDivisionError, TypeError):  # M infinite or complex: l*sqrt(θ) at θ = 0
            warnings.append(
                f"The forces balance at {_point_text(m, q0)}, but the mass matrix is not "
                "defined there (a position function is not differentiable, or leaves its "
                "domain, e.g. a square root at 0): the model does not hold at that point, so it "
                "is left out."
            )
            continue
        if verdict.pole and not _held_at_pole(d, variant, q0, values):
            warnings.append(
                f"Every ${letter(m, 'Q')}_j$ vanishes at {_point_text(m, q0)}, a "
                + (
                    "singular point of the coordinates (no coordinate carries inertia there), "
                    "only because the position does not move to first order in them: beside "
                    "it the force along the path does not shrink to 0 (at a cusp of the wire "
                    "gravity pulls along it)"
                    if verdict.reason.startswith(flat.SINGULAR)
                    else "pole of the coordinates, only because they cannot move in every "
                    "direction there: beside it the forces do not shrink to 0 (a force or "
                    "torque acts along a direction they lose there)"
                )
                + ", so it is not an equilibrium and is left out."
            )
            continue
        verdict.family = root.family or verdict.family
        if variant.ranges and (meaning := branches.meaning(m, q0, values)):
            # a spring passed through its anchor, two masses through each other: said first
            verdict.reason = f"{meaning}. {verdict.reason[:1].upper()}{verdict.reason[1:]}"
        verdicts.append(verdict)
        results.append(_result_json(m, root, free, verdict, q0))
        continua.add(q0, verdict, results[-1])
    order = sorted(range(len(results)), key=lambda i: [abs(v) for v in results[i]["q"].values()])
    results, verdicts = [results[i] for i in order], [verdicts[i] for i in order]
    results, verdicts = _one_per_configuration(m, results, verdicts, values, warnings)
    results, verdicts = _inside_the_model(m, results, verdicts, values, warnings)
    results, verdicts = _where_the_stops_allow(d, results, verdicts, values, warnings)
    continua.describe(results, verdicts)
    if len(results) > MAX_EQUILIBRIA:
        warnings.append(
            f"More than {MAX_EQUILIBRIA} equilibria"
            + (" (a continuum?)" if crowded and not continua.groups else "")
            + f": only the first {MAX_EQUILIBRIA} are listed."
        )
        results, verdicts = results[:MAX_EQUILIBRIA], verdicts[:MAX_EQUILIBRIA]
    families += [v.family for v in verdicts if v.family and v.family not in families]
    steps.append(_stability_step(m, results, verdicts))
    dry = _once(d, "dry friction", "", lambda: _dry_friction(d))
    if dry:
        warnings.append(
            "Dry friction acts here (a force with the sign of a velocity): at rest it can take "
            "any value up to its limit, which the forces at $\\dot q = 0$ above leave out. A "
            "body at rest stays at rest wherever static friction can hold the other forces "
            r"($|F| \le \mu N$)"
            + (": the scene's stop conditions say where." if m.spec.stops else ".")
        )
    if results:  # a family is said only where one of its members is listed
        warnings[:0] = families
    elif left_out:
        warnings.append(
            "No equilibrium the system can be in: the forces balance only at the states left out "
            "above."
        )
    elif not dry and not any(w.startswith(_EDGE) for w in warnings):
        kinked = any(
            k.args[0].has(*m.q) for c in conditions for k in (sp.S.Zero + c).atoms(sp.Abs, sp.sign)
        )
        warnings.append(
            # a force −k sgn(x − y) balances on the kink x = y only, where no slope leads
            "No equilibrium found, but the forces at rest have kinks (|u| or sgn(u) of the "
            "coordinates): a point on a kink of several coordinates, or one where the forces on "
            "either side point toward it (0 lies between their one-sided values) is not "
            "searched for, and there may be one there."
            if kinked
            else "No equilibrium: the forces at rest never balance at these parameters."
        )
    return {"steps": [s.to_json() for s in steps], "equilibria": results, "warnings": warnings}


#: The order in which one configuration's verdicts are kept: the most cautious first.
_CAUTION = ("unstable", "marginal", "gyroscopically stable", "stable", "asymptotically stable")


def _one_per_configuration(m, results, verdicts, values, warnings):
    """Coordinates that name the same configuration twice (θ = 0 of a sphere with any φ): one
    entry, with the most cautious verdict among them. Where the potential depends on φ the
    search found the pole at a dozen φ, each linearized in θ along its own φ only ('stable' at
    one, 'unstable' at another, for one point). Only for particles, whose positions are the
    whole configuration (a rigid body's orientation is not in its position)."""
    if len(results) < 2 or any(b.kind != "particle" for b in m.bodies):
        return results, verdicts
    groups: list[tuple[tuple, list[int]]] = []
    for i, r in enumerate(results):
        where = _configuration(m, [r["q"][n] for n in m.coordinate_names], values)
        if where is None:
            return results, verdicts
        for key, members in groups:
            scale = max(1.0, *map(abs, key), *map(abs, where))
            if all(abs(a - b) <= 1e-9 * scale for a, b in zip(key, where, strict=True)):
                members.append(i)
                break
        else:
            groups.append((where, [i]))
    if len(groups) == len(results):
        return results, verdicts
    kept = []
    for _, members in groups:
        best = min(members, key=lambda i: (_CAUTION.index(verdicts[i].kind), members.index(i)))
        kept.append(best)
        if len(members) > 1:
            r = results[best]
            warnings.append(
                f"{len(members)} equilibria found name one configuration (a pole of the "
                "coordinates, where one of them is undefined): listed once, at "
                + ", ".join(f"{k} = {x:.4g}" for k, x in r["q"].items())
                + f", with the most cautious verdict among them ({verdicts[best].kind})."
            )
    kept.sort()
    return [results[i] for i in kept], [verdicts[i] for i in kept]


def _configuration(m: Any, q0: list[float], values: dict) -> tuple[float, ...] | None:
    """Every body's position at q0 (t = 0), as numbers; None where one is not a number."""
    at = {**values, **{q: sp.Float(x) for q, x in zip(m.q, q0, strict=True)}}
    at[m.names["t"]] = sp.S.Zero
    out = []
    for b in m.bodies:
        for component in b.position.to_matrix(m.N):
            try:
                out.append(float(sp.S.Zero + component.xreplace(at).evalf()))
            except (TypeError, ValueError):
                return None
    return tuple(out)


def _point_text(m: Any, q0: list[float]) -> str:
    return ", ".join(f"{n} = {x:.4g}" for n, x in zip(m.coordinate_names, q0, strict=True))


def _undefined_position(m: Any, q0: list[float], values: dict) -> str | None:
    """The first body (or point) whose position is not a finite real vector at q0, if any: the
    conditions and M may be real where a position is not (l*log(θ) at θ < 0 enters M as 1/θ²)."""
    at = {**values, **{q: sp.Float(x) for q, x in zip(m.q, q0, strict=True)}}
    at[m.names["t"]] = sp.S.Zero  # a frame turned by a drive (Ω t): any instant will do
    for name, r in m.positions.items():
        if r == Vector(0):
            continue
        for component in r.to_matrix(m.N):
            value = component.xreplace(at).evalf()
            if value.free_symbols:
                continue  # not a number here (nothing this check can say)
            try:
                z = complex(value)
            except (TypeError, ValueError, ZeroDivisionError):
                return name
            if not (math.isfinite(z.real) and abs(z.imag) <= 1e-12 * max(1.0, abs(z.real))):
                return name
    return None


def _singular_at(mass_matrix: sp.Matrix, at: dict) -> bool:
    """Is M singular at this state (smallest eigenvalue ≤ 1e-12 × largest), or not a number?"""
    try:
        M = np.array(mass_matrix.xreplace(at).evalf(), dtype=float)
    except (TypeError, ValueError):
        return False
    eig = np.linalg.eigvalsh((M + M.T) / 2)
    return bool(np.all(np.isfinite(eig))) and eig[0] <= 1e-12 * max(abs(eig[-1]), 1e-300)


def _unphysical_inertia(
    m: Any, mass_matrix: sp.Matrix, q0: list[float], values: dict
) -> str | None:
    """What is wrong at q0 with a mass or inertia that depends on the coordinates, naming its
    field; None if nothing is. The request's own state is refused by the physical-limit checks
    (422), but an equilibrium elsewhere can sit where m (2 − x) is −1: its linearization then
    answered "unstable" for a body that cannot exist, or "stable" with no inertia at all."""
    at = {**values, **{q: sp.Float(x) for q, x in zip(m.q, q0, strict=True)}}
    at[m.names["t"]] = sp.S.Zero

    def number(e: Any) -> float | None:
        try:
            x = float(e.xreplace(at))
        except (TypeError, ValueError):
            return None
        return x if math.isfinite(x) else None

    for where, what, value in m.limits:
        entries = value if isinstance(value, dict) else {"": value}
        moving = [k for k, v in entries.items() if isinstance(v, sp.Basic) and v.has(*m.q)]
        if not where.endswith((".mass", ".inertia")) or not moving:
            continue
        here = {k: number(v) for k, v in entries.items()}
        if where.endswith(".mass"):
            x = here[""]
            if x is not None and x <= 0:
                return f"{what} {to_plain(value)} is {x:g} there ({where}): a mass must be > 0"
            continue
        for k in (k for k in ("ixx", "iyy", "izz") if k in moving):
            x = here[k]
            if x is not None and x < 0:
                return (
                    f"{what} has {k} = {to_plain(entries[k])} = {x:g} there ({where}.{k}): a "
                    "moment of inertia is ∫ r² dm ≥ 0"
                )
            if x == 0 and _singular_at(mass_matrix, at):  # ≥ 0 is allowed (a thin rod)
                return (
                    f"{what} has {k} = {to_plain(entries[k])} = 0 there ({where}.{k}): the body "
                    "has no inertia about that axis, the mass matrix is singular, and the "
                    "motion near the point is not determined"
                )
        errors = _inertia_errors(where, what, here)  # not positive semidefinite, I₁ + I₂ < I₃
        if errors:
            return f"{errors[0]['message']} there ({errors[0]['field']})"
    return None


def _idle_at(m: Any, conditions: list[sp.Expr], values: dict) -> list[int]:
    """Coordinates whose force at rest vanishes for every value of them at these parameters
    (a pendulum's Q_θ = −m g l sin θ with g = 0; an Atwood machine's Q_x = (m₁ − m₂) g with
    m₁ = m₂) and that no other condition holds: every value is an equilibrium. Searched for
    points, the family came out as a score of sampled 'marginal' equilibria ('a continuum?')."""
    at = [c.xreplace(values) for c in conditions]
    zero = [
        j
        for j, (c, a) in enumerate(zip(conditions, at, strict=True))
        if c != 0 and _vanishes(c, a, values)
    ]
    return [j for j in zero if not any(a.has(m.q[j]) for a in at)]


def _vanishes(c: sp.Expr, at: sp.Expr, values: dict) -> bool:
    """Is the condition c, at these values (``at``), zero whatever the coordinates? A number
    left over is judged against its terms' sizes: m₁ g − m₂ g with m₁ = m₂ is 0 up to rounding."""
    if at == 0 or at.is_zero is True:
        return True
    if at.free_symbols or not at.is_number:
        return False
    try:
        size = sum(abs(complex(a.xreplace(values))) for a in sp.Add.make_args(sp.expand(c)))
        return abs(complex(at)) <= 1e-12 * size
    except (TypeError, ValueError):
        return False


def _zeroed(d: Derivation, zeros: tuple) -> Variant:
    """M and the forcing with the parameters in ``zeros`` set to 0 exactly (once per such set):
    k (ℓ − ℓ₀) d/ℓ becomes k d, a smooth force through the anchor. An entry that the 0 would
    make infinite (1/ℓ with ℓ = 0) is left as derived, for the numbers to judge as before."""
    m, w = d.model, d.work
    if not zeros:
        return Variant(m, w.mass_matrix, w.forcing, [])
    to_zero = {p: sp.S.Zero for p in zeros}

    def zeroed(e: sp.Expr) -> sp.Expr:
        out = e.xreplace(to_zero)
        return e if out.has(sp.zoo, sp.nan, sp.oo, -sp.oo) else out

    return Variant(m, w.mass_matrix.applyfunc(zeroed), w.forcing.applyfunc(zeroed), [])


def _inside_values(m: Any, idle: list[int]) -> dict[int, float]:
    """The member of a family shown for each idle coordinate declared positive: its value 0,
    shown for the others, is the edge the spec excludes (the turntable's r = 0 at k = mΩ², a
    pole where the polar coordinates cannot linearize). Its initial value when that is inside,
    else 1."""
    out = {}
    for j in idle:
        name = m.coordinate_names[j]
        if name in m.spec.positive_coordinates:
            try:
                start = float(m.spec.initial.get(name, 1.0))
            except (TypeError, ValueError):
                start = 1.0
            out[j] = start if math.isfinite(start) and start > 0 else 1.0
    return out


def _idle_note(m: Any, idle: list[int], everything: bool, inside: dict[int, float]) -> str:
    names = ", ".join(m.coordinate_names[j] for j in idle)
    shown = ", ".join(
        f"{m.coordinate_names[j]} = {inside[j]:.4g}"
        if j in inside
        else f"{m.coordinate_names[j]} = 0"
        for j in idle
    )
    excluded = (
        " (0 is excluded: "
        + ", ".join(m.coordinate_names[j] for j in inside)
        + " is declared positive)"
        if inside
        else ""
    )
    if everything:
        return (
            f"No force acts at rest at these parameters (every ${letter(m, 'Q')}_j$ "
            r"vanishes at $\dot q = 0$): "
            "every configuration is an equilibrium (a family), none held by a restoring force: the "
            "list shows one of them, and what a nudge does there."
        )
    return (
        f"At these parameters no force acts at rest along {names} (its $Q$ vanishes for every "
        f"value of it): every value of {names} is an equilibrium (a family); the list shows "
        f"{shown} of each{excluded}."
    )


def _dry_friction(d: Derivation) -> bool:
    """Does a force jump with the sign of a velocity at rest, as Coulomb friction does? Each
    |u|, sgn(u) of a velocity is split into its sides (|u| = ±u, sgn u = ±1) and the sides
    compared at q̇ = 0: −c|v|v and c (sgn(v)|v| − v) ≡ 0 have one value there, and a
    quadratic drag was 'dry friction acts here'. A comparison sympy cannot settle counts as a
    jump (the warning is the cautious side)."""
    m = d.model
    qds = [sp.Dummy(f"v{j}", real=True) for j in range(len(m.qd))]
    to_real = {**dict.fromkeys(m.qdd, sp.S.Zero), **dict(zip(m.qd, qds, strict=True))}
    rest = dict.fromkeys(qds, sp.S.Zero)
    for Q in d.work.Q:
        e = (sp.S.Zero + Q).xreplace(to_real)
        kinks = [
            k for k in e.atoms(sp.sign, sp.Abs, sp.Heaviside) if k.args and k.args[0].has(*qds)
        ]
        if not kinks:
            continue
        arguments = sorted({k.args[0] for k in kinks}, key=sp.default_sort_key)
        if len(arguments) > MAX_KINKS_AT_REST or any(
            u.has(sp.sign, sp.Abs, sp.Heaviside) for u in arguments
        ):
            return True
        sides = []
        for signs in itertools.product((1, -1), repeat=len(arguments)):
            side = dict(zip(arguments, signs, strict=True))
            piece = e.xreplace({k: _side(k, side[k.args[0]]) for k in kinks})
            sides.append(piece.replace(sp.DiracDelta, lambda *a: sp.S.Zero).xreplace(rest))
        if any(sp.simplify(a - sides[0]) != 0 for a in sides[1:]):
            return True
    return False


def _inside_the_model(m, results, verdicts, values, warnings):
    """Leave out equilibria past a declared stop (a mass beyond the pulley, a block off the
    incline): the equations have them, the system they model does not."""
    rest = {**dict.fromkeys(m.qd, sp.S.Zero), m.names["t"]: sp.S.Zero}
    kept, out = [], []
    declared = [
        st for st in m.stops[: len(m.spec.stops)] if st.when is not None and st.crossing == "falls"
    ]
    for r, v in zip(results, verdicts, strict=True):
        coordinates = zip(m.coordinate_names, m.q, strict=True)
        point = {**values, **rest, **{q: sp.Float(r["q"][n]) for n, q in coordinates}}
        past = []
        for st in declared:
            try:
                value = float(st.when.xreplace(point))  # one pass: q̇(t) before the q(t) in it
            except (TypeError, ValueError):
                continue
            if value < 0:
                past.append(st.name)
        (out if past else kept).append((r, v, past))
    if out:
        names = sorted({n for _, _, past in out for n in past})
        warnings.append(
            f"{len(out)} equilibri{'um' if len(out) == 1 else 'a'} of the equations "
            f"{'lies' if len(out) == 1 else 'lie'} where "
            f"the model does not hold (past the stop {', '.join(names)}) and "
            f"{'is' if len(out) == 1 else 'are'} left out."
        )
    return [r for r, _, _ in kept], [v for _, v, _ in kept]


def _where_the_stops_allow(d: Derivation, results, verdicts, values, warnings):
    """Leave out equilibria where a declared stop that needs Newton's method says the model
    does not hold (the ladder hanging through the floor at θ = π, where the wall would have to
    pull): the same test /simulate applies to its initial state, so a "start near" there is a
    422 and the panel says so first. Stops given by `when` are judged by `_inside_the_model`."""
    m = d.model
    if not any(st.when is None for st in m.stops[: len(m.spec.stops)]) or not results:
        return results, verdicts
    from mechanics.numeric import compile_derivation
    from mechanics.stops import refuse_passed_stops

    try:
        c = _once(d, "compiled", "", lambda: compile_derivation(d))
        named = {str(p): float(x) for p, x in values.items()}
        params = [named[k] for k in c.parameters]
    except (SpecError, KeyError):  # a stop /simulate refuses as a field error: nothing to judge
        return results, verdicts
    kept, out = [], []
    for r, v in zip(results, verdicts, strict=True):
        y0 = np.array([*(r["q"][q] for q in c.coordinates), *[0.0] * (c.n + c.extras)])
        try:
            refuse_passed_stops(c, params, y0)
        except SpecError as exc:
            held = [e["message"] for e in exc.errors if "does not hold" in e["message"]]
            if held:
                out.append((r, held[0]))
                continue
        kept.append((r, v))
    for r, why in out:
        warnings.append(
            f"The forces balance at {', '.join(f'{k} = {x:.4g}' for k, x in r['q'].items())}, "
            f"but {why}: a run cannot start there, so it is left out."
        )
    return [r for r, _ in kept], [v for _, v in kept]


_NOT_SMOOTH = (
    r"the forces are not differentiable at rest (a $\operatorname{sgn}(\dot q)$ of Coulomb "
    "friction, say), so there "
    "is no linearization: the linear test cannot decide"
)
_NOT_SMOOTH_WARNING = (
    "Stability is undecided where the forces are not smooth at rest (dry friction): "
    "those equilibria are listed as marginal."
)


class _BeyondDoubles(ArithmeticError):
    """The linearization at an equilibrium is not finite in double precision."""


class _ConditionsOverflow(_BeyondDoubles):
    """The conditions themselves are not finite at a closed-form root (Ω = 1e308: Ω² R cos θ
    overflows at θ = 0, and 0 · ∞ says nothing): no verdict on the root can be trusted."""

    def __init__(self, q0: list[float]) -> None:
        super().__init__()
        self.q0 = q0


def _beyond_doubles(d: Derivation, parameters: dict, q0: list[float], exc: Exception) -> SpecError:
    """A 422 naming the parameters whose size broke the linearization (m₂ = 1e265 beside
    m₁ = 1 makes M singular to double precision; Ω = 1e308 makes K infinite)."""
    m = d.model
    values = {f"parameters.{k}": float(v) for k, v in _checked(d, parameters).items()}
    at = ", ".join(f"{q} = {v:.4g}" for q, v in zip(m.coordinate_names, q0, strict=True))
    # plain words: a 422 message is not typeset, and a bare M there read as a cart's mass
    what = (
        "the linearization (its mass, velocity and stiffness matrices) overflows double precision"
    )
    if isinstance(exc, _ConditionsOverflow):
        what = "the conditions of equilibrium overflow double precision"
    elif isinstance(exc, np.linalg.LinAlgError):
        what = "the mass matrix is singular to double precision"
    error = overflow_error(values, [f"parameters.{k}" for k in parameters], f"{what} at {at}")
    return SpecError([error])


def _result_json(m: Any, root: Root, free: list[int], v: Verdict, q0: list[float]) -> dict:
    names = m.coordinate_names
    return {
        "q": {names[j]: float(q0[j]) + 0.0 for j in range(len(m.q))},
        "symbolic": {names[j]: to_plain(root.symbolic[j]) for j in root.symbolic},
        "symbolic_latex": {names[j]: to_latex(root.symbolic[j]) for j in root.symbolic},
        "free": [names[j] for j in free],
        "exists_when": root.exists,
        "exists_when_latex": root.exists_latex,
        "found_by": root.how,
        "stable": v.stable,
        "kind": v.kind,
        "reason": v.reason,
        "eigenvalues": [[float(z.real), float(z.imag)] for z in v.eigenvalues],
        "frequencies": v.frequencies,
        "modes": v.modes,
        "mode_phases": v.phases,
    }


def _at_rest(v: Variant) -> list[sp.Expr]:
    m = v.model
    rest = {**dict.fromkeys(m.qdd, 0), **dict.fromkeys(m.qd, 0)}
    return [tidy(fj.xreplace(rest), m) for fj in v.forcing]


def _drop_idle_drive(d: Derivation, c: sp.Expr, values: dict) -> sp.Expr:
    """Terms with explicit t that vanish at these parameters (a drive set to 0) are dropped."""
    m = d.model
    timed = _once(d, "timed terms", c, lambda: _timed_terms(c, m))
    idle = tuple(a for a in timed if a.xreplace(values) == 0)
    return _once(d, "without", (c, idle), lambda: tidy(c - sp.Add(*idle), m)) if idle else c


def _timed_terms(c: sp.Expr, m: Any) -> tuple[sp.Expr, ...]:
    """The terms of c with explicit t (a drive): expanding is sympy work, done once per c."""
    if not explicit_time(c, m):
        return ()
    return tuple(a for a in sp.Add.make_args(sp.expand(c)) if explicit_time(a, m))


def _checked(d: Derivation, parameters: dict[str, float]) -> dict[str, float]:
    m = d.model
    errors = []
    for name, value in parameters.items():
        if name not in m.params:
            errors.append({"field": f"parameters.{name}", "message": f"unknown parameter '{name}'"})
        elif not math.isfinite(value):
            errors.append({"field": f"parameters.{name}", "message": "must be a finite number"})
        elif m.params[name].is_nonnegative and value < 0:
            errors.append({"field": f"parameters.{name}", "message": "must be ≥ 0"})
    if errors:
        raise SpecError(errors)
    check_mass_matrix(d, parameters)  # a zero mass has no equilibria to speak of: 422
    return {**m.spec.parameters, **parameters}


def _virtual_work_step(d: Derivation, conditions: list[sp.Expr]) -> Step:
    """The step is the same for every parameter value (a slider move asks again): its lines are
    built once per derivation, a fresh Step each time (callers append to its lines)."""
    known = d.__dict__.setdefault("_virtual_work_lines", {})
    key = tuple(conditions)
    if key not in known:
        known[key] = _virtual_work_lines(d, conditions)
    Q, V = letter(d.model, "Q"), letter(d.model, "V")
    # the forces step's own notation: Q_j is every applied force, Q_j^{NC} the part not in V
    text = (
        "Constraint forces do no virtual work, so only the applied forces enter: "
        rf"$\delta W = \sum_j {Q}_j\,\delta q_j$ with "
        rf"${Q}_j = {Q}_j^{{NC}} - \partial {V}/\partial q_j$ evaluated at rest "
        r"($\dot q = 0$; where a frame turns at a prescribed rate, the equations of motion at "
        r"$\dot q = \ddot q = 0$). The $\delta q_j$ are arbitrary, so each "
        f"${Q}_j$ must vanish (notes II.A, eq. 18)."
    )
    return Step("virtual_work", "Equilibrium by virtual work", text, list(known[key]))


def _virtual_work_lines(d: Derivation, conditions: list[sp.Expr]) -> list[Line]:
    m = d.model
    lines = []
    for b in m.bodies:
        delta = sum(
            (b.position.diff(q, m.N) * sp.Symbol(rf"\delta {to_latex(q)}") for q in m.q),
            sp.S.Zero * m.N.x,
        )
        if delta != 0:
            lines.append(
                Line(
                    f"delta r {b.name}",
                    rf"\delta\vec{{r}}_{{\text{{{b.name}}}}} = "
                    f"{to_latex(delta.simplify())}",
                    f"delta r_{b.name}",
                )
            )
    return lines + _condition_lines(d, conditions)


def _condition_lines(d: Derivation, conditions: list[sp.Expr], where: str = "") -> list[Line]:
    m = d.model
    Q = letter(m, "Q")
    return [
        Line(
            f"Q_{name} at rest{where}",
            rf"{Q}_{{{to_latex(q)}}}\big|_{{\dot q = 0}} = {to_latex(c)} = 0",
            f"Q_{name} = {to_plain(c)} = 0{where}",
        )
        for name, q, c in zip(m.coordinate_names, m.q, conditions, strict=True)
    ]


# --- which coordinates are angles ------------------------------------------------------------


def _periods(d: Derivation) -> dict[int, float]:
    """2π for every coordinate the equations are 2π-periodic in: it enters only through
    sin/cos (…) of integer multiples of itself. Declared units alone do not make an angle
    periodic (a torsion spring ½kθ² is not), and a posted spec often has no units at all."""
    m, w = d.model, d.work
    dummies = {s: sp.Dummy() for s in (*m.qdd, *m.qd)}
    q_syms = {q: sp.Dummy(f"q{j}") for j, q in enumerate(m.q)}
    exprs = [e.xreplace(dummies).xreplace(q_syms) for e in (*w.forcing, *w.mass_matrix)]
    periods = {}
    for j, q in enumerate(m.q):
        x = q_syms[q]
        present = any(e.has(x) for e in exprs)
        is_angle = m.spec.units.get(m.coordinate_names[j]) == "rad"
        if present and all(_enters_periodically(e, x) for e in exprs):
            periods[j] = 2 * math.pi
        elif not present and is_angle:
            periods[j] = 2 * math.pi
    return periods


def _enters_periodically(expr: sp.Expr, x: sp.Symbol) -> bool:
    if expr == x:
        return False
    if not expr.has(x):
        return True
    if isinstance(expr, _TRIG):
        arg = expr.args[0]
        c = arg.diff(x)
        if c.is_integer and c != 0 and not (arg - c * x).has(x):
            return True
    return all(_enters_periodically(a, x) for a in expr.args)


def _wrap(value: float, period: float | None) -> tuple[float, int]:
    """Angles into (−π, π]; returns the value and the whole turns taken off."""
    if period is None:
        return value, 0
    turns = math.floor((value + math.pi) / (2 * math.pi))
    wrapped = value - 2 * math.pi * turns
    if wrapped <= -math.pi + 1e-12:
        wrapped += 2 * math.pi
        turns -= 1
    return wrapped, turns


def _same(a: dict[int, float], b: dict[int, float], periods: dict[int, float]) -> bool:
    for j in set(a) | set(b):
        x, y = a.get(j, 0.0), b.get(j, 0.0)
        diff = x - y
        if j in periods:
            diff = math.remainder(diff, periods[j])
        if abs(diff) > 1e-6 * (1 + abs(x)):
            return False
    return True


# --- the roots: closed form, checked and completed by a numeric search -----------------------


def _equilibrium_points(v, conditions, values, periods) -> tuple[list[Root], list[str], str | None]:
    """The roots, notes, and why sympy gave no closed form (None when it did): the caller says
    that once, over every side of the springs' anchors (one sentence per side said 'each was
    recognised in closed form' and 'none was' of the same system)."""
    m = v.model
    notes: list[str] = []
    free = [j for j, c in enumerate(conditions) if c == 0]
    bound = [j for j in range(len(m.q)) if j not in free]
    if not bound:
        return [Root({}, {}, "always")], notes, None
    to_zero = {m.q[j]: 0 for j in free}
    eqs = [conditions[j].xreplace(to_zero) for j in bound]
    family = _linear_family(m, eqs, bound, values)
    if family is not None and _in_range(v, family.numeric, values):
        return [family], notes, None
    system = _System(v, eqs, bound, values, periods)
    symbolic = _symbolic(m, eqs, bound, values, periods, _ranges(v, bound, to_zero))
    numeric = _numeric_search(system)
    roots: list[Root] = []
    for root in symbolic or []:
        x = np.array([[root.numeric[j]] for j in bound])
        if not system.in_range(x)[0]:
            continue  # the other side of a spring's anchor, or a positive coordinate < 0
        if not system.residual_ok(x)[0]:
            with np.errstate(all="ignore"):  # not finite here nor beside it: no pole, overflow
                finite = np.all(np.isfinite(system.f(np.hstack([x, x + 1e-6]))), axis=0)
                if not finite.any():
                    raise _ConditionsOverflow([root.numeric.get(j, 0.0) for j in range(len(m.q))])
            notes.append(
                "sympy gave "
                + ", ".join(
                    f"{m.coordinate_names[j]} = {to_plain(root.symbolic[j])}" for j in bound
                )
                + ", which does not satisfy the conditions at these parameters: left out."
            )
            continue
        if not any(_same(root.numeric, r.numeric, periods) for r in roots):
            roots.append(root)
    confirmed = 0
    for x in numeric:
        point = dict(zip(bound, x, strict=True))
        match = next((r for r in roots if _same(point, r.numeric, periods)), None)
        if match is not None:
            match.how = "closed form, confirmed numerically"
            confirmed += 1
            continue
        closed = _closed_form_guess(m, eqs, bound, point, periods, values)
        if closed is not None:
            # its exact value, not the search's (θ = −1.5·10⁻³⁶ was shown for θ = 0)
            exact = {j: float(closed[j].xreplace(values)) for j in bound}
            roots.append(Root(exact, closed, "always", "numeric search, closed form recognised"))
        else:
            roots.append(Root(point, {}, "numeric", "numeric search"))
    if symbolic is not None and len(roots) > len(symbolic):
        notes.append(
            "The numeric search found equilibria that sympy's closed-form solution missed; "
            "they are listed too."
        )
    if system.timed_out:
        notes.append(
            f"The numeric search stopped at its time limit ({SEARCH_SECONDS:g} s): "
            "equilibria may be missing."
        )
    notes += [
        _edge_note(m, edge)
        for edge in system.edges
        if not roots and _balanced_at_edge(v, conditions, edge, values, system.spread)
    ]
    return roots, notes, _numeric_why(eqs, bound) if symbolic is None else None


def _balanced_at_edge(
    v: Variant, conditions: list[sp.Expr], edge: dict[int, float], values: dict, spread: float
) -> bool:
    """Do the forces really balance at a point where a declared-positive coordinate is 0?
    There the coordinates are singular and Q_j = 0 can be their artefact: an elastic pendulum
    without its spring (k = 0) has Q_r = m g cos θ, Q_θ = −m g r sin θ, both 0 at r = 0,
    θ = π/2, where gravity pulls as ever. The size of the force, Qᵀ M⁻¹ Q (the kinetic metric,
    which undoes the vanishing r² in M_θθ), must shrink as the point is approached from
    inside: like r² for a spring of rest length 0 at its anchor, not at all for gravity."""
    m = v.model
    positive = [j for j in edge if m.coordinate_names[j] in m.spec.positive_coordinates]
    sizes = []
    for eps in (1e-3 * spread, 1e-5 * spread):
        q = [edge.get(j, 0.0) for j in range(len(m.q))]
        for j in positive:
            q[j] = eps
        at = {**values, **{qj: sp.Float(x) for qj, x in zip(m.q, q, strict=True)}}
        at[m.names["t"]] = sp.S.Zero
        try:
            Q = np.array([float(sp.S.Zero + c.xreplace(at)) for c in conditions])
            M = np.array(
                [[float(sp.S.Zero + e.xreplace(at)) for e in row] for row in v.mass_matrix.tolist()]
            )
            sizes.append(float(Q @ np.linalg.solve(M, Q)))
        except (TypeError, ValueError, np.linalg.LinAlgError):
            return False
    far, near = sizes
    return math.isfinite(far) and near <= 1e-2 * far + 1e-300


_EDGE = "The forces balance only at"


def _edge_note(m: Any, edge: dict[int, float]) -> str:
    """Forces that balance only where a declared-positive coordinate is 0 (an elastic pendulum
    with ℓ₀ = 0 and g = 0 rests at its anchor, r = 0): the state exists, its coordinates do not."""
    names = [
        m.coordinate_names[j] for j in edge if m.coordinate_names[j] in m.spec.positive_coordinates
    ]
    at = ", ".join(f"{m.coordinate_names[j]} = {x:.4g}" for j, x in edge.items())
    return (
        f"{_EDGE} {at}, on the edge of the coordinates ({', '.join(names)} is "
        "declared positive: the coordinates are singular where it is 0, e.g. a polar angle "
        "loses its meaning at the origin). The system can rest there, but these coordinates "
        "cannot linearize about it, so it is not listed."
    )


def _in_range(v: Variant, point: dict[int, float], values: dict) -> bool:
    """Is the point inside the variant's ranges (a spring's side of its anchor, a positive
    coordinate > 0)? A family's point outside them is left to the search, as before."""
    m = v.model
    ranges = [m.q[j] for j, n in enumerate(m.coordinate_names) if n in m.spec.positive_coordinates]
    at = {**values, **{q: sp.Float(point.get(j, 0.0)) for j, q in enumerate(m.q)}}
    try:
        return all(float(r.xreplace(at)) > 1e-9 for r in [*ranges, *v.ranges])
    except (TypeError, ValueError):
        return False


def _linear_family(m: Any, eqs: list[sp.Expr], bound: list[int], values: dict) -> Root | None:
    """Conditions that are linear in the coordinates at these values (A q = b) but of rank
    below their number, and consistent: a family of equilibria, q* + span(null A), such as
    two masses coupled only to each other (x₁ = x₂, any value). Returned as one Root, the
    point nearest q = 0, with the family's dimension and its description; None otherwise,
    for the search to find points. Searched for points, the family came out as two dozen
    sampled 'marginal' equilibria and 'a continuum?'."""
    qs = [m.q[j] for j in bound]
    at = [e.xreplace(values) for e in eqs]
    try:
        if not all(a.is_polynomial(*qs) and sp.Poly(a, *qs).total_degree() <= 1 for a in at):
            return None
        A = np.array([[float(a.diff(q)) for q in qs] for a in at])
        b = -np.array([float(a.xreplace(dict.fromkeys(qs, 0))) for a in at])
    except (TypeError, ValueError, sp.PolynomialError):
        return None
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):
        return None
    u, sv, vt = np.linalg.svd(A)
    scale = float(np.max(np.abs(sv), initial=0.0))
    rank = int(np.sum(sv > 1e-10 * scale)) if scale > 0 else 0
    if rank == len(qs):
        return None  # one point: sympy's closed form says it better
    x = np.linalg.pinv(A, rcond=1e-10) @ b if rank else np.zeros(len(qs))
    size = float(np.max(np.abs(b), initial=0.0)) + scale * float(np.max(np.abs(x), initial=0))
    if np.max(np.abs(A @ x - b), initial=0.0) > 1e-9 * max(size, 1e-300):
        return None  # inconsistent: no equilibrium, which the search finds too
    x = np.where(np.abs(x) <= 1e-12 * max(1.0, float(np.max(np.abs(x)))), 0.0, x)
    null = vt[rank:]
    names = [m.coordinate_names[j] for j in bound]
    directions = []
    for v in null:
        v = v / v[np.argmax(np.abs(v))]
        v = np.where(np.abs(v) < 1e-12, 0.0, v)
        directions.append("(" + ", ".join(f"{c:.4g}" for c in v + 0.0) + ")")
    point = "(" + ", ".join(f"{c:.4g}" for c in x + 0.0) + ")"
    dim = len(null)
    s = "" if dim == 1 else "s"
    description = (
        f"At these parameters the conditions are linear in {', '.join(names)} and only {rank} "
        f"of the {len(qs)} are independent: the equilibria form a {dim}-parameter family, "
        f"({', '.join(names)}) = {point} + "
        + " + ".join(f"s{'' if dim == 1 else k + 1} {d}" for k, d in enumerate(directions))
        + f" for any s{'' if dim == 1 else '1…s' + str(dim)} (a line of equilibria"
        + ("" if dim == 1 else ", or a plane")
        + f"). The list shows the one nearest 0; along the family direction{s} no force acts, "
        "so a nudge there drifts on (neutral)."
    )
    return Root(
        dict(zip(bound, (float(c) for c in x), strict=True)),
        {},
        "always",
        "linear conditions: a family",
        family_dim=dim,
        family=description,
    )


@dataclass(frozen=True)
class _ClosedForm:
    """One solution of the conditions in closed form: per bound coordinate its expression, the
    conditions under which it exists, and a numpy function of the parameters that evaluates it."""

    exprs: tuple[sp.Expr, ...]
    exists: str
    exists_latex: str
    evaluate: Callable[..., Any]


def _ranges(v: Variant, bound: list[int], to_zero: dict) -> tuple[sp.Expr, ...]:
    """Where the conditions hold as derived: a declared-positive coordinate > 0, a spring along
    a line on its side of the anchor (ℓ = x, not |x|), each to be > 0."""
    m = v.model
    positive = [m.q[j] for j in bound if m.coordinate_names[j] in m.spec.positive_coordinates]
    return tuple(r.xreplace(to_zero) for r in [*positive, *v.ranges])


def _symbolic(m, eqs, bound, values, periods, ranges=()) -> list[Root] | None:
    """Closed-form roots with their existence conditions, or None when sympy cannot."""
    psyms = tuple(sorted(values, key=str))
    solved = _solved(tuple(eqs), tuple((j, m.q[j]) for j in bound), psyms, tuple(ranges))
    if solved is None:
        return None
    if not solved and not all(_never_zero(e, values) for e in eqs):
        return None
    point = list(np.array([complex(values[p]) for p in psyms], dtype=complex))
    out = []
    for sol in solved:
        with np.errstate(all="ignore"):
            try:
                computed = [complex(x) for x in sol.evaluate(*point)]
            except (TypeError, ValueError, ZeroDivisionError, OverflowError):
                continue
        numeric, symbolic = {}, {}
        for j, expr, value in zip(bound, sol.exprs, computed, strict=True):
            if abs(value.imag) > 1e-12 or not math.isfinite(value.real):
                break
            wrapped, turns = _wrap(value.real, periods.get(j))
            numeric[j] = wrapped
            symbolic[j] = expr - 2 * sp.pi * turns if turns else expr
        else:
            out.append(Root(numeric, symbolic, sol.exists, exists_latex=sol.exists_latex))
    return out


def _not_asked(eqs: tuple, n: int) -> str:
    """Why sympy's solver is not called on these conditions ('' when it is): each limit keeps a
    request bounded, and the note then says so instead of 'sympy could not'."""
    if n > 2:
        return "sympy is not asked to solve more than two conditions at once"
    if sum(sp.count_ops(e) for e in eqs) > SYMBOLIC_OPS_LIMIT:
        return "The conditions are too long to hand to sympy's solver"
    if n == 2 and any(e.has(*_TRIG) for e in eqs):
        return (
            "sympy is not asked to solve two trigonometric conditions at once (it can take minutes)"
        )
    if n == 2 and not all(closed_form.rational_in_coordinates(e) for e in eqs):
        return (
            "sympy is not asked to solve two conditions at once with radicals or other "
            "non-rational functions of the coordinates in them (it can take minutes)"
        )
    if any(closed_form.mixes_trig(e, _TRIG) for e in eqs):
        return (
            "A coordinate enters a condition both inside and outside a trigonometric function "
            "(k θ = m g l sin θ), which has no closed form in general: sympy is not asked (it "
            "can take a minute to say so)"
        )
    return ""


def _numeric_why(eqs: list, bound: list[int]) -> str:
    """Why there is no closed form: sympy not asked, or asked and failed."""
    return (
        _not_asked(tuple(eqs), len(bound)) or "sympy could not solve the conditions in closed form"
    )


def _numeric_note(why: str, roots: list[Root]) -> str:
    """What happened when sympy gave no closed form (``why``): the search found the roots, and
    those it recognised (a simple value that satisfies the conditions for any parameter values)
    carry a closed form. A note that said 'sympy could not' while every entry showed one (the
    double pendulum's 0 and π) told the student two things."""
    recognised = sum(1 for r in roots if r.symbolic)
    if not roots:
        return f"{why}, and a numeric search found no equilibrium."
    if recognised == len(roots):
        found = (
            "each was recognised in closed form (values that satisfy the conditions for any "
            "parameter values)"
        )
    elif recognised:
        found = (
            f"{recognised} of the {len(roots)} were recognised in closed form; the others are "
            "known as numbers only"
        )
    else:
        found = "none was recognised in closed form: they are known as numbers only"
    return f"{why}: the equilibria were found by a numeric search, and {found}."


@functools.lru_cache(maxsize=512)
def _solved(eqs: tuple, bound: tuple, psyms: tuple, ranges: tuple = ()) -> list[_ClosedForm] | None:
    """sympy's closed-form solutions of the conditions, once per scene (they hold for every
    parameter value; a slider move only evaluates them), or None when sympy cannot solve.
    ``bound``: (index, q) of each coordinate solved for; the index names its symbol, which
    orders the variables of sympy's polynomial algebra (and so how long it takes)."""
    qs = tuple(q for _, q in bound)
    if _not_asked(eqs, len(qs)):
        return None  # the numeric search covers it
    subs = {q: sp.Symbol(f"_q{j}", real=True) for j, q in bound}
    back = {v: k for k, v in subs.items()}
    try:
        sols = sp.solve(
            [e.xreplace(subs) for e in eqs], list(subs.values()), dict=True, check=False
        )
    except (NotImplementedError, ValueError, TypeError):
        return None
    out = []
    for sol in sols:
        if len(sol) < len(qs) or any(v.free_symbols & set(subs.values()) for v in sol.values()):
            return None
        exprs, conditions = _unpiece(tuple(sol[subs[q]].xreplace(back) for q in qs))
        conditions += [c for expr in exprs for c in _existence(expr)]
        conditions += _in_range_when(ranges, dict(zip(qs, exprs, strict=True)), exprs)
        exists = " and ".join(plain for plain, _ in conditions) or "always"
        latex = r" \ \text{and}\  ".join(latex for _, latex in conditions)
        out.append(_ClosedForm(exprs, exists, latex, _evaluator(list(exprs), psyms)))
    return out


def _evaluator(exprs: list[sp.Expr], psyms: tuple) -> Callable[..., list]:
    """numpy for speed; sympy's own evaluation where numpy has no name for a value (zoo)."""
    try:
        return sp.lambdify(psyms, exprs, modules="numpy", dummify=True)
    except (KeyError, NameError, TypeError, SyntaxError):

        def evaluate(*point: complex) -> list:
            values = {
                p: sp.Float(v.real) + sp.I * sp.Float(v.imag)
                for p, v in zip(psyms, map(complex, point), strict=True)
            }
            return [e.xreplace(values).evalf() for e in exprs]

        return evaluate


def _never_zero(expr, values) -> bool:
    return not expr.free_symbols - set(values) - {t}


def _unpiece(exprs: tuple) -> tuple[tuple, list[tuple[str, str]]]:
    """sympy's Piecewise((−L0, L0 > 0), (nan, True)) is −L0 where L0 > 0 and nothing otherwise:
    the value and its condition, stated (it was shown whole, beside 'always')."""
    out, conditions = [], []
    for expr in exprs:
        if (
            isinstance(expr, sp.Piecewise)
            and len(expr.args) == 2
            and expr.args[1].expr is sp.nan
            and expr.args[1].cond == sp.true
        ):
            value, cond = expr.args[0]
            out.append(value)
            conditions.append((to_plain(cond), to_latex(cond)))
        else:
            out.append(expr)
    return tuple(out), conditions


def _in_range_when(ranges: tuple, solution: dict, exprs: tuple) -> list[tuple[str, str]]:
    """The closed form's own validity: it solves the conditions of one side of a spring's anchor
    (or of a positive coordinate) and exists only where it lands on that side, and only where
    its denominators do not vanish. A bead on a spinning rod, x = L0 k/(k − m Ω²), was
    'always' while it exists for k > m Ω² only (at k = m Ω² it divides by 0, below it lands on
    the other side, where the spring pulls the other way)."""
    out = []
    for r in ranges:
        inside = sp.cancel(sp.together(r.xreplace(solution)))
        if inside.is_positive:
            continue
        out.append((f"{to_plain(inside)} > 0", rf"{to_latex(inside)} > 0"))
    if out:  # a quotient > 0 already says its denominator is not 0
        return out
    dens = []
    for expr in exprs:
        den = sp.denom(sp.together(expr))
        if isinstance(den, sp.Add) and den.free_symbols and den not in dens:
            dens.append(den)
    return [(f"{to_plain(den)} != 0", rf"{to_latex(den)} \ne 0") for den in dens]


def _existence(expr: sp.Expr) -> list[tuple[str, str]]:
    """acos(u), asin(u) need |u| ≤ 1; sqrt(u) needs u ≥ 0 — the notes' 'only when Ω² > g/R'.
    Each condition as (plain text, LaTeX)."""
    out = []
    for f in expr.atoms(sp.acos, sp.asin):
        u = f.args[0]
        out.append((f"|{to_plain(u)}| <= 1", rf"\left|{to_latex(u)}\right| \le 1"))
    for p in expr.atoms(sp.Pow):
        if p.exp == sp.Rational(1, 2) and not p.base.is_nonnegative:
            out.append((f"{to_plain(p.base)} >= 0", rf"{to_latex(p.base)} \ge 0"))
    return out


def _closed_form_guess(m, eqs, bound, point, periods, values) -> dict[int, sp.Expr] | None:
    """A numeric root at a simple value (kπ/12 for an angle, 0 or ± a parameter, or twice one,
    otherwise) that makes every condition vanish for any parameter values is a closed form that
    holds always. Matched at the values asked for (a slider's), not the spec's defaults; every
    match is tried (at M = 2, L0 = 1 the root x = −2 is −2 L0, not −M)."""
    hits = []
    for j in bound:
        x = point[j]
        candidates = [sp.S.Zero]
        if j in periods:
            candidates += [sp.pi * k / 12 for k in range(-11, 13) if k]
        else:  # ± a parameter, or ± twice one (a spring's other side: x = −2ℓ₀)
            for sym in m.params.values():
                if float(values.get(sym, 0)) != 0:
                    candidates += [sym, -sym, 2 * sym, -2 * sym]
        hit = [c for c in candidates if abs(float(c.xreplace(values)) - x) < 1e-7]
        if not hit:
            return None
        hits.append(hit)
    for n, choice in enumerate(itertools.product(*hits)):
        if n >= 16:  # a bound on the symbolic checks; past it the root stays a number
            return None
        guesses = dict(zip(bound, choice, strict=True))
        if _holds_always(m, [e.xreplace({m.q[j]: guesses[j] for j in bound}) for e in eqs]):
            return guesses
    return None


def _holds_always(m, exact: list[sp.Expr]) -> bool:
    """Every condition vanishes at three random sets of parameter values."""
    rng = np.random.default_rng(1)
    for _ in range(3):
        trial = {s: sp.Float(rng.uniform(0.5, 2.0)) for s in m.params.values()}
        for e in exact:
            try:
                value = complex(e.xreplace(trial).evalf())
            except (TypeError, ValueError):
                return False
            scale = sum(abs(complex(a.xreplace(trial).evalf())) for a in sp.Add.make_args(e))
            if not abs(value) <= 1e-10 * (1 + scale):
                return False
    return True


class _System:
    """The conditions as vectorized numpy functions of the bound coordinates, with their
    Jacobian, a residual scale per condition, and the coordinates' range (a declared positive
    coordinate > 0; a spring along a line on the side it was derived for)."""

    def __init__(self, v: Variant, eqs, bound, values, periods):
        m = v.model
        self.n = len(bound)
        self.bound = bound
        self.periods = [periods.get(j) for j in bound]
        ranges = [m.q[j] for j in bound if m.coordinate_names[j] in m.spec.positive_coordinates]
        self.positive = len(ranges)  # the first ranges: declared-positive coordinates
        self.edges: list[dict[int, float]] = []
        ranges += v.ranges
        psyms = tuple(sorted(values, key=str))
        f, jac, scale, in_range = _conditions_numeric(
            tuple(eqs), tuple(m.q[j] for j in bound), tuple(m.q), tuple(ranges), psyms
        )
        # numpy scalars: an overflow is inf (and judged), not Python's OverflowError
        point = list(np.array([float(values[p]) for p in psyms], dtype=float))
        self.f = functools.partial(f, point=point)
        self.jac = functools.partial(jac, point=point)
        self.scale = functools.partial(scale, point=point)
        self.ranges = functools.partial(in_range, point=point)
        self.param_values = sorted({abs(float(v)) for v in values.values()} - {0.0})
        self.spread = max([1.0, *self.param_values])
        self.typical = 1.0
        self.timed_out = False
        self.kinks = _kink_points(m, eqs, bound, values)

    def residual_ok(self, X: np.ndarray) -> np.ndarray:
        """Columns of X where every condition vanishes to round-off of its own terms."""
        F, S = self.f(X), self.scale(X)
        ok = np.abs(F) <= 1e-9 * (S + 1e-3 * self.typical)
        return np.all(ok & np.isfinite(F), axis=0)

    def in_range(self, X: np.ndarray) -> np.ndarray:
        R = self.ranges(X)
        return np.all(R > 1e-9, axis=0) if len(R) else np.ones(X.shape[1], dtype=bool)

    def on_edge(self, X: np.ndarray) -> np.ndarray:
        """Columns of X at 0 of a declared-positive coordinate and inside every other range."""
        R = self.ranges(X)
        if not self.positive:
            return np.zeros(X.shape[1], dtype=bool)
        edge = np.any(np.abs(R[: self.positive]) <= 1e-9, axis=0)
        others = np.all(R[: self.positive] > -1e-9, axis=0) & np.all(
            R[self.positive :] > 1e-9, axis=0
        )
        return edge & others


def _kink_points(m: Any, eqs: list, bound: list[int], values: dict) -> list[tuple[int, float]]:
    """Where an argument of |u| or sgn(u) in the conditions vanishes, for u linear in one
    coordinate: (index among the bound ones, value). A force −k sgn(x) balances at x = 0 only,
    where Newton has no slope to follow (V = k|x| was 'no equilibrium'): the search's points
    are snapped there too. Candidates only: the residual decides."""
    xs = {m.q[j]: i for i, j in enumerate(bound)}
    numbers = {p: sp.Float(v) for p, v in values.items()}
    kinks = set().union(*((sp.S.Zero + e).atoms(sp.Abs, sp.sign) for e in eqs))
    points: list[tuple[int, float]] = []
    for kink in sorted(kinks, key=sp.default_sort_key)[:8]:
        u = kink.args[0].xreplace(numbers)
        inside = [q for q in xs if u.has(q)]
        if len(inside) != 1 or sp.count_ops(u) > 40:
            continue
        x = sp.Dummy("x", real=True)
        u = u.xreplace({inside[0]: x})
        if u.free_symbols != {x}:
            continue
        try:
            slope = u.diff(x)
            if not slope.free_symbols and slope != 0:  # linear in x: one root
                points.append((xs[inside[0]], float(-u.xreplace({x: 0}) / slope)))
        except (TypeError, ValueError):
            continue
    return points


def _snapped(X: np.ndarray, kinks: list[tuple[int, float]]) -> np.ndarray:
    """The search's points with one coordinate put on a kink: the others found by Newton."""
    return np.hstack(
        [X] + [np.vstack([*X[:i], np.full(X.shape[1], c), *X[i + 1 :]]) for i, c in kinks]
    )


@functools.lru_cache(maxsize=512)
def _conditions_numeric(eqs: tuple, qs: tuple, all_qs: tuple, ranges: tuple, psyms: tuple):
    """The conditions, their Jacobian, their terms' sizes and the coordinates' ranges as numpy
    functions of the bound coordinates and the parameters, once per scene: a slider move only
    calls them with new numbers."""
    # real: d|x|/dx is then sgn x (of a complex x, Derivative(re(x), x), which numpy cannot
    # print: V = k|x| was a 500), and d sgn(x)/dx = 2δ(x), 0 off the kink where Newton steps
    xs = [sp.Dummy(f"x{j}", real=True) for j in range(len(qs))]
    to_x = dict(zip(qs, xs, strict=True))
    to_x.update({q: 0 for q in all_qs if q not in to_x})
    f = [e.xreplace(to_x).replace(sp.DiracDelta, lambda *a: sp.S.Zero) for e in eqs]
    jac = [fi.diff(x).replace(sp.DiracDelta, lambda *a: sp.S.Zero) for fi in f for x in xs]
    return (
        _vectorized(f, xs, psyms),
        _vectorized(jac, xs, psyms),
        _vectorized([sp.Add(*(sp.Abs(a) for a in sp.Add.make_args(fi))) for fi in f], xs, psyms),
        _vectorized([r.xreplace(to_x) for r in ranges], xs, psyms),
    )


def _vectorized(exprs: list[sp.Expr], xs: list[sp.Symbol], psyms: tuple = ()):
    """numpy function of X (n × S) and the parameters' values (in psyms' order) returning
    len(exprs) × S, nan where not real or finite."""
    fn = sp.lambdify([*xs, *psyms], exprs, modules="numpy", dummify=True)

    def call(X: np.ndarray, point: list[float] = ()) -> np.ndarray:
        if not exprs:
            return np.zeros((0, X.shape[1]))
        with np.errstate(all="ignore"):
            out = fn(*X, *point)
        rows = []
        for o in out:
            a = np.broadcast_to(np.asarray(o), X.shape[1:])
            if np.iscomplexobj(a):
                a = np.where(np.abs(a.imag) > 1e-12, np.nan, a.real)
            rows.append(a.astype(float))
        return np.array(rows)

    return call


def _numeric_search(system: _System) -> list[list[float]]:
    """Newton's method from a capped grid of starts, all at once; converged, in-range roots,
    wrapped and deduplicated. Bounded: MAX_STARTS starts, MAX_NEWTON_STEPS steps, and a clock."""
    n = system.n
    X = _starts(system).T  # n × S
    with np.errstate(all="ignore"):
        S = system.scale(X)
    finite = S[np.isfinite(S)]
    system.typical = float(np.median(finite)) if finite.size else 1.0
    step_cap = np.array([1.0 if p else 0.5 * system.spread for p in system.periods])
    deadline = time.monotonic() + SEARCH_SECONDS
    active = np.ones(X.shape[1], dtype=bool)  # starts still moving: the others are done
    for _ in range(MAX_NEWTON_STEPS):
        if time.monotonic() > deadline:
            system.timed_out = True
            break
        Y = X[:, active]
        F = system.f(Y)
        J = system.jac(Y).reshape(n, n, -1).transpose(2, 0, 1)
        bad = ~(np.all(np.isfinite(F), axis=0) & np.all(np.isfinite(J), axis=(1, 2)))
        J[bad], F[:, bad] = 0.0, 0.0
        with np.errstate(all="ignore"):
            step = np.einsum("sij,sj->si", np.linalg.pinv(J, rcond=1e-13), F.T).T
        too_far = np.max(np.abs(step) / step_cap[:, None], axis=0)
        step /= np.maximum(too_far, 1.0)
        Y = Y - step
        Y[:, bad] = np.nan
        for i, p in enumerate(system.periods):
            if p:
                Y[i] -= 2 * math.pi * np.floor((Y[i] + math.pi) / (2 * math.pi))
        X[:, active] = Y
        # a start is done once it is lost or its step is below the last bits of its value
        size = np.max(np.abs(step) - 4e-16 * np.abs(Y), axis=0)
        moving = np.isfinite(Y[0]) & ~(size < 1e-15)
        active[np.flatnonzero(active)[~moving]] = False
        if not active.any():
            break
    alive = np.all(np.isfinite(X), axis=0)
    X = X[:, alive]
    if system.kinks:  # every start once more, put on the kink, and where Newton ended
        start = _starts(system).T
        X = _snapped(np.hstack([X, start[:, np.all(np.isfinite(start), axis=0)]]), system.kinks)
    balanced = system.residual_ok(X)
    edge = balanced & ~system.in_range(X) & system.on_edge(X)
    for x in X[:, edge].T[:1]:
        system.edges.append(dict(zip(system.bound, (float(v) + 0.0 for v in x), strict=True)))
    X = X[:, balanced & system.in_range(X)]
    found: list[list[float]] = []
    for x in X.T:
        x = [_wrap(float(v), p)[0] + 0.0 for v, p in zip(x, system.periods, strict=True)]
        point = dict(enumerate(x))
        periods = {i: p for i, p in enumerate(system.periods) if p}
        if not any(_same(point, dict(enumerate(y)), periods) for y in found):
            found.append(x)
    return found


def _grid_point(axes: list[list[float]], index: int) -> tuple[float, ...]:
    """The index-th point of itertools.product(*axes): the last axis varies fastest."""
    point = []
    for axis in reversed(axes):
        index, k = divmod(int(index), len(axis))
        point.append(axis[k])
    return tuple(reversed(point))


def _starts(system: _System) -> np.ndarray:
    """A grid over each coordinate's range (angles: multiples of π/8 in (−π, π]; lengths: 0 and
    ± a ladder up to a few times the largest parameter), sampled down to MAX_STARTS."""
    values, spread = system.param_values, system.spread
    axes = []
    for p in system.periods:
        if p:
            axes.append([k * math.pi / 8 + 0.01 for k in range(-7, 9)])
        else:
            ladder = [spread * 2.0**e for e in range(-4, 3)]
            ladder += [v * 1.1 for v in values if v > 0] + [v * 0.9 for v in values if v > 0]
            axes.append([0.013] + ladder + [-v for v in ladder])
    size = math.prod(len(axis) for axis in axes)
    if size <= MAX_STARTS:
        grid = list(itertools.product(*axes))
    else:  # the grid's points by index (itertools.product's order), never the whole grid
        rng = np.random.default_rng(0)
        grid = [
            _grid_point(axes, i) for i in sorted(rng.choice(size, MAX_STARTS - 1, replace=False))
        ]
        grid.insert(
            0,
            tuple(
                axis[len(axis) // 2 - 1] if p else axis[0]
                for axis, p in zip(axes, system.periods, strict=True)
            ),
        )  # near q = 0 always
    return np.array(grid, dtype=float)


# --- the work of the non-conservative forces --------------------------------------------------

#: The reasons carry their math as $…$ LaTeX, as the steps' prose does, so that the page typesets
#: it and the LaTeX export keeps it math (plain 'e^(3.1 t)' read as a caret and a bracket).
#: The matrices bold, as the matrix-form step writes its mass matrix (and a cart's mass M is not
#: the mass matrix); f is that step's right-hand side.
_LINEARIZED = r"$\mathbf M\,\delta\ddot q + \mathbf C\,\delta\dot q + \mathbf K\,\delta q = 0$"


def _power_symbol(m: Any, at_rest: bool = True) -> str:
    """The power of the velocity-dependent forces in the forces step's letters. Q_j there is
    every applied force (Q_j^NC − ∂V/∂q_j), so the sum is over Q_j^NC, less its part at rest when
    a force acts at rest too (a wind and its drag): that part is in K, not in this power."""
    Q = letter(m, "Q")
    if at_rest:
        return rf"\sum_j ({Q}_j^{{NC}} - {Q}_j^{{NC}}|_{{\dot q = 0}})\,\dot q_j"
    return rf"\sum_j {Q}_j^{{NC}} \dot q_j"  # as the conserved step writes dE/dt


@dataclass(frozen=True)
class Power:
    """What the velocity-dependent non-conservative forces do to the energy near an equilibrium.

    Lagrange–Dirichlet (a minimum of V is stable) rests on E = T + V never growing: it holds when
    their power P = Σ_j Q_j q̇_j is 0 (gyroscopic: a magnetic force) or ≤ 0 (dissipative: a
    damper), not when P has no sign (c ẋ³ pumps energy in at c ẋ⁴, while the linearization
    sees nothing and calls it a minimum). ``kind``: "none", "no work", "dissipative" or
    "no sign"; ``text``: P = … as derived, in $…$, for the sentence."""

    kind: str = "none"
    text: str = ""
    #: "no sign" proven never negative (c ẋ⁴ of an anti-damper c ẋ³): energy is fed in, not
    #: merely possibly fed in.
    feeds: bool = False
    #: The sum the text equates, as LaTeX (the general one when the scene's is not known).
    symbol: str = r"\sum_j (Q_j^{NC} - Q_j^{NC}|_{\dot q = 0})\,\dot q_j"


def _force_power(d: Derivation) -> tuple[sp.Expr, list[sp.Expr], bool, bool]:
    """Once per scene: the velocity-dependent part of the forces' (and torques') power,
    Σ_j (Q_j − Q_j|q̇=0) q̇_j (the part at rest is conservative, in K, or circulatory, seen by
    K's asymmetry); each damper's coefficient c (its power is −c ℓ̇² ≤ 0 while c ≥ 0, a
    dashpot); whether any force depends on a velocity at all; and whether any force that
    does also acts at rest (then the power's symbol subtracts that part)."""
    m = d.model
    turning = _turning(m)  # then Σ Q q̇ ≠ F·v: dampers are judged like any force
    rest = dict.fromkeys(m.qd, sp.S.Zero)
    dampers = [] if turning else [parse(x.c, m.names, field="c") for x in m.spec.dampers]
    power, moves, at_rest = sp.S.Zero, False, False
    for load in m.loads:
        if load.kind == "damper" and not turning:
            continue
        if load.kind == "torque":
            body = next(b for b in m.bodies if b.name == load.on)
            w = body.frame.ang_vel_in(m.N)
        else:
            w = m.velocity(load.on)
        for qd in m.qd:
            Q = load.vector.dot(w.diff(qd, m.N))
            moving = Q - Q.xreplace(rest)
            if moving != 0:
                moves = True
                power += moving * qd
                at_rest = at_rest or Q != moving
    power = sp.expand(power)
    if power != 0 and sp.count_ops(power) <= 400:
        power = tidy(power, m)
    return power, dampers, moves, at_rest


def _power_at(d: Derivation, values: dict, q0: list[float]) -> Power:
    """Power's kind at these parameter values, near q0: 0, provably ≤ 0 (every term a
    non-negative number times an even power, or a quadratic part in q̇ that is negative
    definite at q0, which wins near rest), or neither."""
    m = d.model
    if not m.loads:
        return Power()
    power, dampers, moves, at_rest = _once(d, "power", "", lambda: _force_power(d))
    symbol = _power_symbol(m, at_rest)
    try:
        leaky = any(float(c.xreplace(values)) < 0 for c in dampers)
    except (TypeError, ValueError):
        leaky = True
    if leaky:  # a damper's own share of the sum, which alone can feed energy in
        return Power(
            "no sign", r"$-c\,\dot\ell^2$ of a damper with $c < 0$", _power_symbol(m, False)
        )
    if not moves:
        return Power("dissipative" if dampers else "none", symbol=symbol)
    at = sp.expand(power.xreplace(values)) if power != 0 else power
    # gyroscopic: Q ≠ 0 with q̇, but Σ Q_j q̇_j = 0 (case by case where |q̇| or sign(q̇) appear)
    # exact with the parameters as symbols; with their values (c = 0) floats may leave 1e-17
    if (
        at == 0
        or _once(d, "vanishes", "", lambda: vanishes(power, m))
        or _once(d, "vanishes", at, lambda: vanishes(at, m))
    ):
        return Power("dissipative" if dampers else "no work", symbol=symbol)
    proven = _once(d, "never positive", at, lambda: _never_positive(m, at))
    text = f"${symbol} = {_once(d, 'power latex', '', lambda: to_latex(power))}$"
    if dampers:  # their share, −c ℓ̇² ≤ 0, is judged apart and not in the sum shown
        text += " (dampers aside)"
    if proven or _quadratic_wins(m, at, q0):
        return Power("dissipative", text, symbol)
    feeds = _once(d, "never negative", at, lambda: _never_positive(m, -at))
    return Power("no sign", text, symbol, feeds)


def _sign_words(power: Power) -> str:
    """What a power that is not ≤ 0 does, as proven: c ẋ⁴ is never negative (energy is fed in
    whenever the body moves); a power of either sign can feed energy in."""
    if power.feeds:
        return "is never negative: they feed energy in whenever the system moves"
    return "has no sign: they can feed energy in"


def _never_positive(m: Any, power: sp.Expr) -> bool:
    """A proof that P ≤ 0 for every state, or False: P is −(a sum of non-negative terms),
    as written or factored (−c (ẋ − ẏ)²), or a quadratic form q̇ᵀ D(q) q̇ whose D sympy shows
    negative semidefinite for every q. Bounded: a large P is left unproven."""
    real = {s: sp.Dummy(real=True) for s in (*m.q, *m.qd, m.names["t"])}
    if sp.count_ops(power) > 400:
        return False
    p = power.xreplace(real)
    try:
        if (-p).is_nonnegative or (-sp.factor(p)).is_nonnegative:
            return True
        if _never_positive_by_sides(p):
            return True
        v = [real[qd] for qd in m.qd]
        if not sp.Poly(p, *v).is_homogeneous or sp.Poly(p, *v).total_degree() != 2:
            return False
        D = sp.Matrix(len(v), len(v), lambda i, j: p.diff(v[i]).diff(v[j]) / 2)
        return bool(D.is_negative_semidefinite)
    except (TypeError, ValueError, RecursionError, sp.PolynomialError):
        return False


def _never_positive_by_sides(p: sp.Expr) -> bool:
    """P ≤ 0 side by side of each velocity in |v| or sgn(v): v = ±w with w > 0, or v = 0.
    −c sgn(θ̇) θ̇³ is −c|θ̇|³ ≤ 0, which sympy does not see as written (a quadratic drag
    written with sign was 'power has no sign')."""
    kinks = p.atoms(sp.Abs, sp.sign)
    if not kinks:
        return False
    variables = {k.args[0] for k in kinks}
    if len(variables) > 3 or not all(isinstance(u, sp.Symbol) for u in variables):
        return False
    variables = sorted(variables, key=sp.default_sort_key)
    ws = [sp.Dummy(positive=True) for _ in variables]
    for sides in itertools.product(*((w, -w, sp.S.Zero) for w in ws)):
        case = p.xreplace(dict(zip(variables, sides, strict=True)))
        if not ((-case).is_nonnegative or (-sp.factor(case)).is_nonnegative):
            return False
    return True


def _quadratic_wins(m: Any, power: sp.Expr, q0: list[float]) -> bool:
    """Is P = q̇ᵀ D q̇ + O(|q̇|³) with D negative definite at q0? Then P < 0 near rest."""
    rest = dict.fromkeys(m.qd, sp.S.Zero)
    point = {q: sp.Float(x) for q, x in zip(m.q, q0, strict=True)}
    point[m.names["t"]] = sp.S.Zero
    if explicit_time(power, m):
        return False
    try:
        D = np.array(
            [
                [float(power.diff(a).diff(b).xreplace(rest).xreplace(point)) / 2 for b in m.qd]
                for a in m.qd
            ]
        )
    except (TypeError, ValueError):
        return False
    scale = float(np.max(np.abs(D), initial=0.0))
    return scale > 0 and bool(np.all(np.linalg.eigvalsh((D + D.T) / 2) < -1e-9 * scale))


# --- stability from the full linearization ---------------------------------------------------


_NOT_ELEMENTARY = (sp.sign, sp.Abs, sp.DiracDelta, sp.Heaviside, sp.Derivative, sp.Subs)


#: The linearization depends on t (a damper whose c varies in time, c cos t ẋ): its eigenvalues at
#: one instant say nothing of the motion (Floquet's theory would).
_TIMED = "timed"
_TIME_VARYING = (
    f"the linearization {_LINEARIZED} depends on time here (a velocity-dependent force "
    "that varies with $t$): eigenvalues at one instant do not decide, and the linear test cannot"
)


@functools.lru_cache(maxsize=256)
def _linearization(mass: tuple, forcing: tuple, qs: tuple, qds: tuple, qdds: tuple, psyms: tuple):
    """M, K = −∂f/∂q and C = −∂f/∂q̇ at rest as one numpy function of (q, parameters), derived
    once per scene; None where the forces are not smooth at rest, for sympy to judge."""
    rest = {**dict.fromkeys(qdds, 0), **dict.fromkeys(qds, 0)}
    # at rest first (it commutes with ∂/∂q): a damper's terms vanish before they are
    # differentiated, 6.6 s of a damped pair's 11 s
    K = [-_derivative(sp.S.Zero + fj.xreplace(rest), q) for fj in forcing for q in qs]
    C = [-_derivative(fj, qd).xreplace(rest) for fj in forcing for qd in qds]
    M = [sp.S.Zero + e.xreplace(rest) for e in mass]
    if any(e.has(*_NOT_ELEMENTARY) for e in (*M, *K, *C)):
        return None
    xs = [sp.Dummy(f"q{j}") for j in range(len(qs))]
    to_x = dict(zip(qs, xs, strict=True))
    exprs = [[e.xreplace(to_x) for e in group] for group in (M, K, C)]
    if any(e.has(t) for group in exprs for e in group):
        return _TIMED
    return sp.lambdify([*xs, *psyms], exprs, modules="numpy", dummify=True)


class _NotSmooth(ValueError):
    """The forces have a kink or a jump at this equilibrium: no linearization. ``in_position``:
    every kink is one of q alone (V = k|x|), none of a velocity (dry friction's sgn(q̇))."""

    def __init__(self, in_position: bool) -> None:
        super().__init__("not differentiable at rest")
        self.in_position = in_position


#: Kinks at an equilibrium whose sides are compared (2 per kink): beyond, no verdict.
MAX_KINKS_AT_REST = 4


def _piecewise_linearization(v: Variant, q0: list[float], values: dict):
    """M, K, C at rest where the forces hold |u|, sgn(u) or H(u): each kink's argument u that
    vanishes here is split into its sides (|u| = ±u, sgn u = ±1), and the smooth pieces must
    agree, in value and in first derivatives. Then the forces are C¹ here and the pieces'
    common M, K, C is the linearization: a quadratic drag −c|θ̇|θ̇ has C = 0 at rest, which
    'not differentiable, undecided' missed. Pieces that disagree (sgn θ̇ jumps, k|x| bends)
    raise _NotSmooth. Real symbols throughout: d|x|/dx of a complex x is not sgn x."""
    m = v.model
    n = len(m.q)
    qs = [sp.Dummy(f"q{j}", real=True) for j in range(n)]
    qds = [sp.Dummy(f"v{j}", real=True) for j in range(n)]
    to_real = {**dict.fromkeys(m.qdd, sp.S.Zero), **dict(zip(m.qd, qds, strict=True))}
    to_real.update(dict(zip(m.q, qs, strict=True)))
    numbers = {p: sp.Float(x) for p, x in values.items()}
    exprs = [
        sp.S.Zero + e.xreplace(to_real).xreplace(numbers) for e in (*v.mass_matrix, *v.forcing)
    ]
    at = {**dict(zip(qs, map(sp.Float, q0), strict=True)), **dict.fromkeys(qds, sp.S.Zero)}
    kinks = set().union(*(e.atoms(sp.Abs, sp.sign, sp.Heaviside) for e in exprs))
    fixed, split = {}, []
    for kink in sorted(kinks, key=sp.default_sort_key):
        u = kink.args[0]
        if u.has(sp.Abs, sp.sign, sp.Heaviside):
            raise _NotSmooth(not u.has(*qds))
        u0 = complex(u.xreplace(at).evalf())
        if abs(u0.imag) > 1e-12:
            raise _NotSmooth(not u.has(*qds))
        scale = max(1.0, *(abs(float(a.xreplace(at).evalf())) for a in sp.Add.make_args(u)))
        if abs(u0.real) > 1e-12 * scale:
            fixed[kink] = _side(kink, 1 if u0.real > 0 else -1)
        else:
            split.append(kink)
    if len({k.args[0] for k in split}) > MAX_KINKS_AT_REST:
        raise _NotSmooth(not any(k.args[0].has(*qds) for k in split))
    arguments = sorted({k.args[0] for k in split}, key=sp.default_sort_key)
    pieces = []
    for signs in itertools.product((1, -1), repeat=len(arguments)):
        side = dict(zip(arguments, signs, strict=True))
        rule = {**fixed, **{k: _side(k, side[k.args[0]]) for k in split}}
        smooth = [e.xreplace(rule).replace(sp.DiracDelta, lambda *a: sp.S.Zero) for e in exprs]
        if any(e.has(t) for e in smooth[n * n :]):
            return _TIMED
        mass, forcing = smooth[: n * n], smooth[n * n :]
        pieces.append(
            [
                [float(e.xreplace(at)) for e in mass],
                [float(f.xreplace(at)) for f in forcing],
                [-float(f.diff(q).xreplace(at)) for f in forcing for q in qs],
                [-float(f.diff(qd).xreplace(at)) for f in forcing for qd in qds],
            ]
        )
    first = [np.array(x) for x in pieces[0]]
    for piece in pieces[1:]:
        for a, b in zip(first, piece, strict=True):
            size = max(1.0, float(np.max(np.abs(a), initial=0.0)))
            if not np.allclose(a, b, rtol=1e-9, atol=1e-9 * size):
                raise _NotSmooth(not any(u.has(*qds) for u in arguments))
    M, _, K, C = first
    return M.reshape(n, n), K.reshape(n, n), C.reshape(n, n)


def _side(kink: sp.Expr, sign: int) -> sp.Expr:
    """|u|, sgn u or H(u) on the side of u's sign."""
    u = kink.args[0]
    if isinstance(kink, sp.Abs):
        return sign * u
    if isinstance(kink, sp.sign):
        return sp.Integer(sign)
    return sp.Integer(1 if sign > 0 else 0)


def _kink_verdict(d: Derivation, v: Variant, q0: list[float], values: dict, power: Power):
    """An equilibrium at a kink of the forces of q alone (V = k|x| at 0): no linearization, but
    in one coordinate the force itself says what V does on each side. Pushed back from both
    sides, V has a minimum there (a position force in one coordinate has a potential), and with
    forces of q̇ that do no positive work it is stable (Lagrange–Dirichlet); pushed away on a
    side, a nudge that way runs off. In more coordinates no sampling proves a minimum."""
    m = v.model
    if len(m.q) != 1:
        return Verdict("marginal", _KINK, [], [], [], [], None)
    rest = {**dict.fromkeys(m.qdd, sp.S.Zero), **dict.fromkeys(m.qd, sp.S.Zero)}
    numbers = {p: sp.Float(x) for p, x in values.items()}
    f = (sp.S.Zero + v.forcing[0]).xreplace(rest).xreplace(numbers)
    pushes = []
    for side in (1, -1):
        for eps in (1e-4, 1e-6):
            step = side * eps * max(1.0, abs(q0[0]))
            try:
                value = float(f.xreplace({m.q[0]: sp.Float(q0[0] + step)}).evalf())
            except (TypeError, ValueError):
                return Verdict("marginal", _KINK, [], [], [], [], None)
            pushes.append(value * side)
    name = m.coordinate_names[0]
    if all(p < 0 for p in pushes):
        if power.kind == "no sign":
            return Verdict(
                "marginal",
                f"{_KINK_NO_LINEAR}; the force pushes back toward it from both sides (the "
                f"potential has a minimum with a kink here), but the velocity-dependent forces' "
                f"power {power.text} {_sign_words(power)}, so the minimum need "
                "not hold the motion",
                [],
                [],
                [],
                [],
                None,
            )
        return Verdict(
            "stable",
            f"{_KINK_NO_LINEAR}, but the force pushes back toward it from both sides of "
            f"{name}: the potential has a minimum at the kink, and the "
            "velocity-dependent forces do no positive work, so the energy cannot carry a small "
            "motion away: stable by the potential (Lagrange–Dirichlet)",
            [],
            [],
            [],
            [],
            None,
        )
    if any(p > 0 for p in pushes):
        return Verdict(
            "unstable",
            f"{_KINK_NO_LINEAR}, but on one side of it at least the force pushes {name} further "
            "away (the potential falls from the kink): a small displacement that way runs off",
            [],
            [],
            [],
            [],
            None,
        )
    return Verdict("marginal", _KINK, [], [], [], [], None)


_KINK_NO_LINEAR = (
    "the forces are not differentiable at this point (a kink of the potential, as $k|x|$ at "
    "0), so there is no linearization"
)
_KINK = f"{_KINK_NO_LINEAR}: the linear test cannot decide"
_KINK_WARNING = (
    "Some equilibria lie at a kink of the potential (a force that jumps there, as $-k\\,"
    "\\operatorname{sgn} x$ of $V = k|x|$): they have no linearization, and no frequencies "
    "are given for them."
)


@functools.lru_cache(maxsize=4096)
def _derivative(expr: sp.Expr, var: sp.Expr) -> sp.Expr:
    """∂f/∂q of the forcing, once per scene: every equilibrium and every parameter value needs
    the same symbolic derivative, evaluated at different numbers."""
    return expr.diff(var)


def _stability(
    v: Variant,
    q0: list[float],
    free: list[int],
    values: dict,
    family_dim: int = 0,
    power: Power = Power(),
) -> Verdict:
    """M δq̈ + C δq̇ + K δq = 0 with K = −∂f/∂q, C = −∂f/∂q̇ at rest; the eigenvalues λ of the
    first-order system decide (δq ∝ e^{λt}), and why is put in words.

    Every coordinate takes part (a free cart still moves with its pendulum), except one whose
    mass-matrix row vanishes there: a coordinate singularity such as φ at the pole of a sphere.
    Zero eigenvalues are neutral along free (cyclic) coordinates and along the ``family_dim``
    directions of a family of equilibria through q0, undecided otherwise. ``power``: what the
    velocity-dependent forces do to the energy, on which a verdict 'stable by the potential'
    rests.
    """
    m = v.model
    n = len(m.q)
    psyms = tuple(sorted(values, key=str))
    try:
        at_rest = _linearization(
            tuple(v.mass_matrix), tuple(v.forcing), tuple(m.q), tuple(m.qd), tuple(m.qdd), psyms
        )
    except ValueError:  # sympy cannot differentiate |q̇| of q̇(t): the pieces below can
        at_rest = None
    if at_rest is _TIMED:
        return Verdict("marginal", _TIME_VARYING, [], [], [], [], None)
    if at_rest is not None:
        numbers = list(np.array([float(values[p]) for p in psyms], dtype=float))
        with np.errstate(all="ignore"):
            M_, K_, C_ = (np.array(x, dtype=float) for x in at_rest(*q0, *numbers))
        full_M = M_.reshape(n, n)
    else:  # |q̇| q̇ is C¹ at rest, sign(q̇) is not: the smooth pieces decide (_NotSmooth)
        pieces = _piecewise_linearization(v, q0, values)
        if pieces is _TIMED:
            return Verdict("marginal", _TIME_VARYING, [], [], [], [], None)
        full_M, K_, C_ = pieces
    # A row of M that vanishes here (φ at a sphere's pole), relative to the others: an
    # absolute 1e-12 took m = 1e-13 for no inertia at all, and every equilibrium for stable.
    inertia = float(np.max(np.abs(np.diag(full_M)), initial=0.0))
    idx = [j for j in range(n) if abs(full_M[j, j]) > 1e-12 * inertia]
    if not idx:  # the coordinates are singular here (∂r/∂q = 0), the body is not weightless
        forces = _rest_force_function(*(tuple(x) for x in (v.forcing, m.q, m.qd, m.qdd)), psyms)
        kind, reason, check = flat.singular_point(at_rest, forces, q0, numbers if at_rest else [])
        return Verdict(kind, reason, [], [], [], [], None, pole=check)
    if at_rest is not None and _singular(full_M[np.ix_(idx, idx)], 1e-12):
        idx = _off_the_pole(at_rest, full_M, q0, numbers, idx)
    K = K_.reshape(n, n)[np.ix_(idx, idx)]
    C = C_.reshape(n, n)[np.ix_(idx, idx)]
    M = full_M[np.ix_(idx, idx)]
    if not all(np.all(np.isfinite(x)) for x in (M, C, K)):
        raise _BeyondDoubles
    linear = {"M": M, "C": C, "K": K, "coordinates": [m.q[j] for j in idx]}
    n_free = len([j for j in free if j in idx]) + family_dim
    report = None  # the flat directions of K, judged by the higher-order test
    if at_rest is not None and not family_dim and power.kind != "no sign":
        forces = _rest_force_function(*(tuple(x) for x in (v.forcing, m.q, m.qd, m.qdd)), psyms)
        keep = [k for k, j in enumerate(idx) if j not in free]
        report = flat.flat_at(at_rest, forces, q0, numbers, idx, keep, M, C, K)
    kind, reason, lam, vecs = _judged(m, M, C, K, n_free, idx, free, power, report)
    freqs, modes, phases = [], [], []
    if kind != "unstable":
        freqs, modes, phases = _modes(M, C, K, lam, vecs, idx, n)
    vectors = [vecs[: len(idx), i] for i in range(len(lam))]
    verdict = Verdict(kind, reason, list(lam), freqs, modes, phases, linear, vectors)
    verdict.family_dim = report.level if report else 0
    lost = [j for j in range(n) if j not in idx]
    if lost and at_rest is not None and _turns_beside(at_rest, full_M, q0, numbers, idx, lost):
        # Coriolis (or a magnetic force) couples the radial motion to the turn about the pole
        # with a weight ∝ r that vanishes at it: only coordinates regular there see it
        return _pole_in_cartesian(v, at_rest, full_M, q0, numbers, psyms, idx, lost, free, power)
    if lost:
        _at_a_pole(verdict, m, full_M, at_rest, q0, numbers if at_rest else [], idx, lost, free)
    return verdict


def _judged(m, M, C, K, n_free, idx, free, power, report):
    """``_classify`` with the flat directions of K judged by the higher-order test: those
    along which the equilibria form a family count with the free ones, the rest decide."""
    names = [m.coordinate_names[j] for j in idx]
    n_free += report.level if report else 0
    kind, reason, lam, vecs = _classify(M, C, K, n_free, names, turning=_turning(m), power=power)
    shown, latex_names = _eigen_math(lam), [to_latex(m.q[j]) for j in idx]
    single = len([j for j in idx if j not in free]) == 1
    kind, reason = flat.amend(
        kind, reason, report, latex_names, shown, single, _potential(_turning(m))
    )
    kind, reason = stability.drifting(kind, reason, n_free)  # on a set: neutral, not stable
    if report and report.level:  # the zero modes are a family's, not (only) free coordinates'
        reason = reason.replace("free direction(s)", "free or family direction(s)")
    return kind, reason, lam, vecs


def _turns_beside(at_rest, full_M, q0, numbers, idx, lost) -> bool:
    """Do velocity-linear forces act just off the pole (Coriolis 2mΩ r ṙ φ̇ on a turntable)?
    Their share in the coordinates kept vanishes at it (∝ r), so the linearization in those
    alone loses them, and with them the split of the two modes about the pole."""
    for i in _radial(None, full_M, at_rest, q0, numbers, idx, lost):
        point = list(q0)
        point[i] += 1e-2
        with np.errstate(all="ignore"):
            try:
                M_h, _, C_h = (np.array(x, dtype=float) for x in at_rest(*point, *numbers))
            except (TypeError, ValueError, ZeroDivisionError, OverflowError):
                return True  # nothing to judge by: the Cartesian test below decides or refuses
        scale = max(float(np.max(np.abs(M_h))), 1e-300)
        if not np.all(np.isfinite(C_h)) or np.max(np.abs(C_h)) > 1e-12 * scale:
            return True
    return False


#: The local Cartesian coordinates about a pole, ξ = ρ cos φ and η = ρ sin φ.
_XI, _ETA = sp.Symbol("xi"), sp.Symbol("eta")


def _pole_in_cartesian(v, at_rest, full_M, q0, numbers, psyms, idx, lost, free, power) -> Verdict:
    """The verdict at a pole where velocity-linear forces act, from the full linearization in
    coordinates regular there: ρ (the radial coordinate less its pole value) and the lost
    angle φ become ξ = ρ cos φ, η = ρ sin φ, as a Cartesian description would have them.

    Lagrange's equations transform with the Jacobian J = ∂q/∂p: M_p = Jᵀ M J, C_p = Jᵀ C J at
    rest (the J̇ ṗ term is quadratic in ṗ) and K_p = −∂(Jᵀ f)/∂p. J is singular at the pole,
    but these are smooth in p there; they are evaluated on a ring of points about it and
    extrapolated (Richardson), and two step sizes must agree. Where the chart does not fit (not
    one radial coordinate and one lost angle) or the estimates disagree, the verdict is
    refused as undecided, never guessed: the turntable's origin at k = 1, Ω = 1.5 had been
    'unstable' (the radial row alone, each motion counted twice) where ω = |√(k/m) ± Ω|."""
    m = v.model
    n = len(q0)
    radial = _radial(None, full_M, at_rest, q0, numbers, idx, lost)
    names = [m.coordinate_names[j] for j in range(n)]
    pole_at = "$" + ", ".join(f"{to_latex(m.q[j])} = {_num(q0[j])}" for j in idx) + "$"
    lost_names = ", ".join(f"${to_latex(m.q[j])}$" for j in lost)
    linear = None
    if len(lost) == 1 and len(radial) == 1:
        linear = _cartesian_linearization(v, at_rest, q0, numbers, psyms, radial[0], lost[0])
    if linear is None:
        return Verdict(
            "marginal",
            f"{pole_at} is a pole of the coordinates (any {lost_names} names the same point), "
            "and velocity-linear forces (Coriolis where a frame turns) couple the motion off "
            "it to the turn about it with a weight that vanishes there: these coordinates are "
            "singular at it and cannot linearize the full motion, so the linear test cannot "
            "decide; a Cartesian description of the scene decides it",
            [],
            [],
            [],
            [],
            None,
            pole=True,
        )
    M, C, K, order = linear
    a, b = radial[0], lost[0]
    # ξ and η are free only where both ρ and φ are (k = mΩ² on the turntable: no force at all)
    n_free = len([j for j in free if j not in (a, b)]) + (2 if a in free and b in free else 0)
    local = [_XI if j == a else _ETA if j == b else m.q[j] for j in order]
    shown = ["xi" if j == a else "eta" if j == b else names[j] for j in order]
    kind, reason, lam, vecs = _classify(M, C, K, n_free, shown, turning=_turning(m), power=power)
    freqs: list[float] = []
    if kind != "unstable":
        freqs, _, _ = _modes(M, C, K, lam, vecs, list(range(len(order))), len(order))
    rho = to_latex(m.q[a]) if abs(q0[a]) <= 1e-12 else f"({to_latex(m.q[a])} - {_num(q0[a])})"
    phi = to_latex(m.q[b])
    reason += (
        f"; {pole_at} is a pole of the coordinates (any {lost_names} names the same point), so "
        f"the motion is linearized in the local Cartesian coordinates $\\xi = {rho}\\cos {phi}$, "
        f"$\\eta = {rho}\\sin {phi}$, which are regular there and keep the velocity-linear "
        "terms (Coriolis where a frame turns, damping) that vanish at the pole in the scene's "
        "coordinates; the modes are motions of $\\xi, \\eta$, not of the scene's coordinates, so "
        "none is offered to excite"
    )
    verdict = Verdict(kind, reason, list(lam), freqs, [], [], None, pole=True)
    verdict.linear = {"M": M, "C": C, "K": K, "coordinates": local}
    return verdict


def _cartesian_linearization(v, at_rest, q0, numbers, psyms, a, b):
    """M, C, K at the pole in p = q with (q_a, q_b) → (ξ, η), and the coordinate order of p
    (a's place holds ξ, b's η); None when two step sizes disagree (the chart is not smooth
    there, or the scale of the coordinates is far from the steps)."""
    m = v.model
    n = len(q0)
    psyms_n = numbers
    forces = _rest_force_function(tuple(v.forcing), tuple(m.q), tuple(m.qd), tuple(m.qdd), psyms)

    def chart(p: np.ndarray) -> tuple[list[float], np.ndarray]:
        x, y = p[a], p[b]
        rho = math.hypot(x, y)
        q = list(p)
        q[a] = q0[a] + rho
        q[b] = q0[b] + math.atan2(y, x)
        J = np.eye(n)
        J[a, a], J[a, b] = x / rho, y / rho
        J[b, a], J[b, b] = -y / rho**2, x / rho**2
        return q, J

    def inertia_and_velocity(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q, J = chart(p)
        M_q, _, C_q = (np.array(e, dtype=float).reshape(n, n) for e in at_rest(*q, *psyms_n))
        return J.T @ M_q @ J, J.T @ C_q @ J

    def generalized(p: np.ndarray) -> np.ndarray:
        q, J = chart(p)
        f = np.array(forces(*q, *psyms_n), dtype=float).reshape(n)
        return J.T @ f

    p0 = np.array(q0, dtype=float)
    p0[a] = p0[b] = 0.0

    def estimate(h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ring = []
        for c, s in ((1, 0), (0, 1), (-1, 0), (0, -1)):
            o = np.zeros(n)
            o[a], o[b] = c * h, s * h
            ring.append(o)
        pairs = [inertia_and_velocity(p0 + o) for o in ring]
        M = sum(x for x, _ in pairs) / 4
        C = sum(x for _, x in pairs) / 4
        # smooth through the pole: each side's M_p within O(h²) of the mean. Euler angles at
        # θ = 0 are not (the turn φ + ψ about the axis jumps with the direction of approach)
        size = max(float(np.max(np.abs(M))), 1e-300)
        if any(np.max(np.abs(x - M)) > 1e-2 * size for x, _ in pairs):
            raise ValueError("not smooth at the pole")
        K = np.zeros((n, n))
        for k in range(n):
            e = np.zeros(n)
            e[k] = h
            centres = [np.zeros(n)] if k in (a, b) else ring
            K[:, k] = -sum(
                (generalized(p0 + o + e) - generalized(p0 + o - e)) / (2 * h) for o in centres
            ) / len(centres)
        return M, C, K

    with np.errstate(all="ignore"):
        try:
            rough = [estimate(h) for h in (2e-3, 1e-3)]
            fine = [estimate(h) for h in (1e-3 / 2, 1e-3 / 4)]
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return None
    first = [(4 * f - c) / 3 for c, f in zip(*rough, strict=True)]
    second = [(4 * f - c) / 3 for c, f in zip(*fine, strict=True)]
    if not all(np.all(np.isfinite(x)) for x in (*first, *second)):
        return None
    M, C, K = second
    # a common scale: the size of every term in the equations, per unit displacement/velocity
    size = max(float(np.max(np.abs(M))), 1e-300)
    rate = math.sqrt(max(float(np.max(np.abs(K))), float(np.max(np.abs(C))) ** 2 / size) / size)
    scales = (size, size * rate, size * rate**2)
    for x, y, s in zip(first, second, scales, strict=True):
        if np.max(np.abs(x - y)) > 1e-6 * max(s, 1e-300):
            return None
    M, C, K = (
        np.where(np.abs(x) <= 1e-9 * max(s, 1e-300), 0.0, x)
        for x, s in zip(second, scales, strict=True)
    )
    M = (M + M.T) / 2
    return M, C, K, list(range(n))


@functools.lru_cache(maxsize=64)
def _rest_force_function(forcing: tuple, qs: tuple, qds: tuple, qdds: tuple, psyms: tuple):
    """f at rest (q̇ = q̈ = 0, t = 0) as a numpy function of (q, parameters): the generalized
    forces the pole's Cartesian linearization differentiates."""
    rest = {**dict.fromkeys(qdds, 0), **dict.fromkeys(qds, 0)}
    xs = [sp.Dummy(f"q{j}") for j in range(len(qs))]
    to_x = dict(zip(qs, xs, strict=True))
    f = [(sp.S.Zero + e).xreplace(rest).xreplace(to_x).xreplace({t: sp.S.Zero}) for e in forcing]
    return sp.lambdify([*xs, *psyms], f, modules="numpy", dummify=True)


def _held_at_pole(d: Derivation, v: Variant, q0: list[float], values: dict) -> bool:
    """Is a pole where every Q_j vanishes an equilibrium? There the coordinates lose a
    direction, and Q_j = 0 can be their artefact: a top whose centre of mass is off its axis
    has Q = 0 at θ = 0 (Euler angles) while gravity's torque about the lost axis acts. The size
    of the force in the kinetic metric, Qᵀ M⁻¹ Q, must shrink to 0 as q0 is approached from
    regular points (like ε² at a true equilibrium), not tend to a constant."""
    m = v.model
    psyms = tuple(sorted(values, key=str))
    fn = _once(d, "forces at rest", (v.label, psyms), lambda: _rest_forces(v, psyms))
    numbers = [float(values[p]) for p in psyms]
    direction = np.random.default_rng(3).uniform(-1.0, 1.0, len(m.q))
    sizes = []
    for eps in (1e-3, 1e-5):
        point = list(np.asarray(q0, dtype=float) + eps * direction)
        with np.errstate(all="ignore"):
            try:
                M, f = (np.array(x, dtype=float) for x in fn(*point, *numbers))
                sizes.append(float(f @ np.linalg.solve(M.reshape(len(f), len(f)), f)))
            except (TypeError, ValueError, ZeroDivisionError, np.linalg.LinAlgError):
                return True  # nothing to judge by: keep it, with its pole caveats
    far, near = sizes
    if not (math.isfinite(far) and math.isfinite(near)):
        return True
    return near <= 1e-2 * abs(far) + 1e-300


def _rest_forces(v: Variant, psyms: tuple) -> Callable[..., Any]:
    """M and f at rest (q̇ = q̈ = 0, t = 0) as one numpy function of (q, parameters)."""
    m = v.model
    rest = {**dict.fromkeys(m.qdd, 0), **dict.fromkeys(m.qd, 0)}
    xs = [sp.Dummy(f"q{j}") for j in range(len(m.q))]
    to_x = dict(zip(m.q, xs, strict=True))

    def at_rest(e: sp.Expr) -> sp.Expr:  # q̇, q̈ first: they hold q(t), which t = 0 would undo
        return (sp.S.Zero + e).xreplace(rest).xreplace(to_x).xreplace({t: sp.S.Zero})

    M = [at_rest(e) for e in v.mass_matrix]
    f = [at_rest(e) for e in v.forcing]
    return sp.lambdify([*xs, *psyms], [M, f], modules="numpy", dummify=True)


def _singular(M: np.ndarray, tol: float) -> bool:
    """Is M singular relative to its own size (smallest singular value ≤ tol × largest)?"""
    s = np.linalg.svd(M, compute_uv=False)
    return not s.size or not np.all(np.isfinite(s)) or s[-1] <= tol * max(s[0], 1e-300)


def _off_the_pole(at_rest, full_M, q0, numbers, idx) -> list[int]:
    """The coordinates kept when M is singular at q0 without a vanishing row: Euler angles at
    θ = 0, where φ and ψ turn about one axis (det M = I₃ (I₁ + m h²)² sin²θ). It is a pole of
    the coordinates when M is singular there at other parameter values too and regular beside
    it; then one coordinate per direction without inertia is dropped (the one that direction
    moves most), as φ is at a sphere's pole. Otherwise ``idx`` is returned as it is, and a
    singular M is the parameters' doing (m₂ = 1e265 beside m₁ = 1), refused as before."""
    n = len(q0)
    rng = np.random.default_rng(7)
    others = list(rng.uniform(0.7, 1.4, len(numbers)))
    nearby = list(np.asarray(q0, dtype=float) + rng.uniform(0.05, 0.1, n))
    with np.errstate(all="ignore"):
        try:
            elsewhere = np.array(at_rest(*q0, *others)[0], dtype=float).reshape(n, n)
            beside = np.array(at_rest(*nearby, *numbers)[0], dtype=float).reshape(n, n)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return idx
    if not _singular(elsewhere[np.ix_(idx, idx)], 1e-9) or _singular(beside, 1e-9):
        return idx
    M = full_M[np.ix_(idx, idx)]
    _, s, vt = np.linalg.svd(M)
    null = vt[s <= 1e-9 * s[0]]
    import scipy.linalg

    _, _, pivots = scipy.linalg.qr(null, pivoting=True)
    dropped = {idx[k] for k in pivots[: len(null)]}
    kept = [j for j in idx if j not in dropped]
    return kept if kept and not _singular(full_M[np.ix_(kept, kept)], 1e-9) else idx


def _at_a_pole(verdict, m, full_M, at_rest, q0, numbers, idx, lost, free) -> None:
    """q0 is a coordinate singularity: the rows of M of the coordinates in ``lost`` vanish here
    (φ at θ = 0 of a sphere), so the linearization above is in the others only, and one
    direction of motion is missing from it. The bob at the bottom of a spherical pendulum swings
    in any vertical plane: two modes of equal ω = √(g/l), where θ alone shows one.

    Where the lost coordinate is cyclic (a symmetry turns the system about the pole) and no
    velocity-linear term acts (C = 0: nothing tells one sense of turning from the other), the
    directions that bring the lost coordinate back to life (M_φφ grows like θ² away from the
    pole: θ 'radial') form with it a plane in which the motion is isotropic: each eigenvalue and
    mode that moves a radial coordinate comes twice. Otherwise the missing modes are unknown,
    and the verdict says so rather than show a short list."""
    verdict.pole = True
    lost_names = ", ".join(f"${to_latex(m.q[j])}$" for j in lost)
    where = "$" + ", ".join(f"{to_latex(m.q[j])} = {_num(q0[j])}" for j in idx) + "$"
    inertia = float(np.max(np.abs(full_M), initial=0.0))
    if all(np.max(np.abs(full_M[j])) <= 1e-12 * inertia for j in lost):
        why = f"any {lost_names} names the same point: its row of $\\mathbf M$ vanishes"
    else:  # Euler angles at θ = 0: φ and ψ turn about one axis
        why = (
            "$\\mathbf M$ is singular here for every parameter value, not for these numbers only: "
            "a turn "
            f"of {lost_names} is one the other coordinates make too, so any {lost_names} names "
            "the same configuration up to them"
        )
    pole = (
        f"{where} is a pole of the coordinates ({why}), so only "
        f"{', '.join(f'${to_latex(m.q[j])}$' for j in idx)} was linearized"
    )
    radial = _radial(m, full_M, at_rest, q0, numbers, idx, lost)
    cyclic = all(j in free for j in lost)
    C = verdict.linear["C"] if verdict.linear else None
    if not cyclic:
        # V depends on the lost coordinate: the other directions off the pole were not tested
        verdict.reason += (
            f"; {pole}: only the directions off it along {lost_names} = its value here were "
            "tested, the others cannot be in these coordinates, so the list of modes may be "
            "incomplete"
        )
        if verdict.kind in STABLE_KINDS:
            verdict.kind = "marginal"
            verdict.reason += " and the linear test cannot decide"
        return
    if not radial or C is None or np.any(np.abs(C) > 0):
        verdict.reason += (
            f"; {pole}: the modes that turn about it are not found in these coordinates (a "
            "velocity-linear force can split them), so the list of modes may be incomplete"
        )
        return
    columns = [idx.index(j) for j in radial]
    twins = [
        z
        for z, vec in zip(verdict.eigenvalues, verdict.vectors, strict=True)
        if np.max(np.abs(vec[columns])) > 1e-9 * max(1.0, float(np.max(np.abs(vec))))
    ]
    modes = list(zip(verdict.frequencies, verdict.modes, verdict.phases, strict=True))
    modes += [
        (f, mode, phase) for f, mode, phase in modes if max(abs(mode[j]) for j in radial) > 1e-9
    ]
    modes.sort(key=lambda fmp: fmp[0])
    before = _eigen_math(np.array(verdict.eigenvalues))
    verdict.eigenvalues = _eigen_sorted(np.array([*verdict.eigenvalues, *twins]))
    verdict.reason = verdict.reason.replace(before, _eigen_math(np.array(verdict.eigenvalues)))
    verdict.frequencies = [f for f, _, _ in modes]
    verdict.modes = [mode for _, mode, _ in modes]
    verdict.phases = [phase for _, _, phase in modes]
    radial_names = ", ".join(f"${to_latex(m.q[j])}$" for j in radial)
    verdict.reason += (
        f"; {pole}. By the symmetry in {lost_names} each motion of {radial_names} comes twice, "
        "in two perpendicular planes: "
        + (
            "it falls away in both, at the same rate"
            if verdict.kind == "unstable"
            else r"two degenerate modes of equal $\omega$"
        )
        + ", which these coordinates cannot tell apart at the pole"
    )


def _radial(m, full_M, at_rest, q0, numbers, idx, lost) -> list[int]:
    """The coordinates that move the system off the pole: M_φφ grows like their square."""
    if at_rest is None:
        return []
    inertia = float(np.max(np.abs(np.diag(full_M)), initial=0.0))
    n, out = len(q0), []
    for i in idx:
        h = 1e-2
        point = list(q0)
        point[i] += h
        with np.errstate(all="ignore"):
            M_h = np.array(at_rest(*point, *numbers)[0], dtype=float).reshape(n, n)
        if all(abs(M_h[j, j]) > 1e-9 * inertia for j in lost) and not _singular(M_h, 1e-9):
            out.append(i)
    return out


def _turning(m: Any) -> str:
    """Does a position move with time by prescription (a hoop spun at Ω)? Then K is the
    Hessian of the effective potential, V less the centrifugal term, not of V: the bead's
    V = −mgR cos θ has its minimum at θ = 0, where the spinning hoop's bead is unstable.
    "frame" when a frame turns at a prescribed angle (the centrifugal term is its share),
    "moving" when only a point is moved (a support at x = v t: no frame turns), "" otherwise."""
    if not any(
        explicit_time(component, m) for r in m.positions.values() for component in r.to_matrix(m.N)
    ):
        return ""
    return "frame" if _frame_turns(m) else "moving"


def _frame_turns(m: Any) -> bool:
    """Is a frame's angle prescribed in time (Ω t)?"""
    for i, f in enumerate(m.spec.frames):
        try:
            if explicit_time(parse(f.angle, m.names, field=f"frames[{i}].angle"), m):
                return True
        except SpecError:
            continue
    return False


def _classify(M, C, K, n_free, names, *, turning: str = "", power: Power = Power()):
    n = len(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam, vecs = np.linalg.eig(A)
    if not np.any(C) and np.max(np.abs(K - K.T), initial=0.0) <= 1e-9 * np.max(np.abs(K)):
        with contextlib.suppress(np.linalg.LinAlgError, ValueError):  # M not definite: eig's
            lam, vecs = stability.conservative_eigenvalues(M, K)
    order = _eigen_order(lam)
    lam, vecs = lam[order], vecs[:, order]
    scale = max(1.0, float(np.max(np.abs(lam))))
    tol = stability.growth_tolerance(A, lam, np.linalg.solve(M, K))
    if tol > 1e-7 * scale:  # K singular: the zero modes' round-off (±4·10⁻⁸) reads 0
        lam = np.where(np.abs(lam) <= tol, 0.0, lam)
    k_shown = np.linalg.eigvalsh((K + K.T) / 2)  # what the sentences quote: K as displayed
    # The tests below judge K and C per unit of inertia (L⁻¹ K L⁻ᵀ with M = L Lᵀ: eigenvalues
    # ω² in 1/s²), so that no choice of mass or length unit moves them across a tolerance: with
    # K itself, m = 1e-10 made a pendulum's bottom 'singular, cannot decide'.
    try:
        inverse = np.linalg.inv(np.linalg.cholesky((M + M.T) / 2))
        K, C = inverse @ K @ inverse.T, inverse @ C @ inverse.T
    except np.linalg.LinAlgError:
        pass  # M not positive definite: judge K and C as they are
    Ks, Cs = (K + K.T) / 2, (C + C.T) / 2
    k_norm = max(float(np.max(np.abs(K))), 1e-300)
    symmetric = np.max(np.abs(K - K.T)) <= 1e-9 * k_norm
    damped = np.max(np.abs(Cs), initial=0.0) > 1e-12 * max(1.0, float(np.max(np.abs(C))))
    gyroscopic = np.max(np.abs(C - Cs), initial=0.0) > 1e-12
    k_eigs = np.linalg.eigvalsh(Ks)
    k_tol = 1e-9 * max(1.0, float(np.max(np.abs(k_eigs))))
    k_null = int(np.sum(np.abs(k_eigs) <= k_tol))
    k_pd_off_free = symmetric and int(np.sum(k_eigs > k_tol)) == n - n_free and k_null == n_free
    c_psd = np.all(np.linalg.eigvalsh(Cs) >= -1e-9 * max(1.0, float(np.max(np.abs(C)))))
    shown = _eigen_math(lam)
    if np.max(lam.real) > tol:
        grow = lam[np.argmax(lam.real)]
        reason = (
            rf"an eigenvalue has positive real part ($\lambda = {_z(grow)}$): a small "
            rf"displacement grows like $e^{{{_num(grow.real)}\,t}}$"
        )
        if not symmetric:
            reason += "; " + _circulatory(grow, tol)
        elif np.min(k_eigs) < -k_tol and not gyroscopic:
            reason += (
                f"; $\\mathbf K$ has a negative eigenvalue: the {_potential(turning)} has no "
                "minimum here"
            )
        return "unstable", reason, lam, vecs
    zero = np.abs(lam) <= max(1e-6 * scale, tol)
    if n_free == n:
        # what a nudge does without a restoring force depends on the velocity-linear terms
        if gyroscopic:
            nudge = (
                f"the {_gyroscopic(turning, power)} terms turn a nudge in velocity into a bounded "
                "loop, "
                "not a drift, but $\\mathbf K$ is singular in every direction and nonlinear terms "
                "decide "
                "(neutral at best)"
            )
        elif damped:
            nudge = (
                "damping brings a nudge in velocity to rest at a nearby point, and nothing "
                "pulls it back (neutral, not stable)"
            )
        else:
            nudge = (
                "a nudge in velocity drifts on without a force pulling it back (neutral, not "
                "stable)"
            )
        return (
            "marginal",
            "every coordinate is free: no force acts at rest in any direction ($\\mathbf K$ "
            "vanishes), so "
            f"every nearby configuration is an equilibrium too, and {nudge}; eigenvalues {shown}",
            lam,
            vecs,
        )
    if not symmetric:
        # no potential stands behind K: only the eigenvalues of the full linearization speak
        on_axis = lam[np.abs(lam.real) <= tol]
        if not on_axis.size:
            return (
                "asymptotically stable",
                f"every eigenvalue has negative real part ({shown}): every small motion dies "
                f"out, {_CIRCULATORY}",
                lam,
                vecs,
            )
        return (
            "marginal",
            f"{_CIRCULATORY[0].upper()}{_CIRCULATORY[1:]}; no eigenvalue has positive real part, "
            f"but some lie on the imaginary axis ({shown}): the linear test cannot decide "
            "(nonlinear terms, or any damping, can tip circulatory forces into flutter)",
            lam,
            vecs,
        )
    if k_null > n_free:
        return (
            "marginal",
            "$\\mathbf K$ is singular in a direction that is not a free coordinate (the motion's "
            "eigenvalues "
            f"{shown}): the quadratic approximation is flat there, so the linear test cannot "
            "decide; higher-order terms do (a bifurcation point, or a family of equilibria)",
            lam,
            vecs,
        )
    free_note = (
        "; the zero eigenvalues belong to the free direction(s), along which the system stays "
        "where it is put (a family of equilibria), and a nudge in velocity along them drifts on"
        if np.any(zero)
        else ""
    )
    moving = lam[~zero]
    if moving.size and np.all(moving.real < -tol) and not np.any(zero):
        return (
            "asymptotically stable",
            f"every eigenvalue has negative real part ({shown}): damping makes every "
            "small motion die out",
            lam,
            vecs,
        )
    if k_pd_off_free and c_psd and power.kind == "no sign":
        return (
            "marginal",
            f"$\\mathbf K$ is positive definite (the {_potential(turning)} has a minimum here) and "
            "no "
            f"eigenvalue has positive real part ({shown}), but the velocity-dependent forces' "
            f"power {power.text} {_sign_words(power)}, which the "
            "linearization does not see, so the minimum need not hold the motion "
            "(Lagrange–Dirichlet needs forces that do no positive work) and the linear test "
            f"cannot decide{free_note}",
            lam,
            vecs,
        )
    if k_pd_off_free and c_psd:
        reason = (
            f"$\\mathbf K$ is positive definite, so the {_potential(turning)} has a minimum here"
        )
        if n_free:  # K is singular along the free directions: definite only off them
            reason = (
                f"$\\mathbf K$ is positive definite off the {n_free} free direction(s), so the "
                f"{_potential(turning)} has a minimum across them"
            )
        if gyroscopic or damped:  # only then is there a velocity-linear term to speak of
            reason += "; velocity-linear terms cannot undo that (Thomson–Tait)"
        if power.kind == "no work":
            reason += (
                "; the velocity-dependent forces do no work (their power "
                f"${power.symbol} = 0$), so the energy cannot grow"
            )
        elif power.kind == "dissipative" and power.text:
            reason += (
                f"; the velocity-dependent forces' power {power.text} is $\\le 0$ here: they "
                "only take energy out"
            )
        if damped:
            reason += ", and damping makes the motion decay"
        # the λ are the linearized motion's, not K's (a student read "K ... (eigenvalues ±2.4i)"
        # as K having imaginary eigenvalues)
        return "stable", reason + f" (the motion's eigenvalues {shown}){free_note}", lam, vecs
    on_axis = moving[np.abs(moving.real) <= tol]
    semisimple = _semisimple(A, on_axis, scale)
    if (
        symmetric
        and gyroscopic
        and not damped
        and semisimple
        and moving.size == on_axis.size
        and power.kind != "no sign"
    ):
        return (
            "gyroscopically stable",
            "$\\mathbf K$ is not positive definite (its eigenvalues "
            f"${', '.join(_num(k) for k in k_shown)}"
            f"$), but the {_gyroscopic(turning, power)} terms (in $\\mathbf C$) keep every "
            "eigenvalue on "
            "the imaginary "
            f"axis without repeated defective ones ({shown}): the linearized motion stays "
            "bounded. Any damping would destroy this (Kelvin–Tait–Chetaev), and nonlinear terms "
            "may too",
            lam,
            vecs,
        )
    if not semisimple:
        why = "a repeated eigenvalue on the imaginary axis lacks a full set of eigenvectors"
    elif power.kind == "no sign":
        why = (
            f"the velocity-dependent forces' power {power.text} has no sign (they "
            "can feed energy in)"
        )
    else:
        why = (
            "$\\mathbf K$ is not positive definite and no gyroscopic term accounts for the "
            "stability"
        )
    return (
        "marginal",
        f"no eigenvalue has positive real part ({shown}), but {why}: the linear test cannot "
        f"decide, nonlinear terms do{free_note}",
        lam,
        vecs,
    )


_CIRCULATORY = (
    "$\\mathbf K$ is not symmetric: position-dependent non-conservative (circulatory) forces act, "
    "a "
    "follower load say, so no potential stands behind $\\mathbf K$ and its eigenvalues say nothing "
    "of a "
    "minimum; only the eigenvalues of the full linearization decide"
)


def _circulatory(grow: complex, tol: float) -> str:
    """Why an equilibrium under circulatory forces is lost: flutter or divergence."""
    if abs(grow.imag) > tol:
        return (
            f"{_CIRCULATORY}: flutter, a complex pair ${_z(grow)}$ and its conjugate with positive "
            "real part, an oscillation that grows"
        )
    return f"{_CIRCULATORY}: divergence, a real positive eigenvalue, a drift that grows"


def _gyroscopic(turning: str, power: Power) -> str:
    """The velocity-linear terms by their source: Coriolis where a frame turns at a prescribed
    rate (T has terms linear in q̇), forces that do no work (a magnetic one) otherwise."""
    forces = power.kind == "no work"
    source = "Coriolis" if turning == "frame" else "the prescribed motion's"
    if turning and forces:
        return f"gyroscopic ({source}, and forces that do no work)"
    if turning:
        return f"gyroscopic ({source})"
    if forces:
        return "gyroscopic (forces that do no work, like a magnetic one)"
    return "gyroscopic"


def _eigen_order(lam: np.ndarray) -> list[int]:
    """The order the eigenvalues are listed in, the frequencies' order: the non-oscillating
    ones first (largest real part first), then each conjugate pair together (+i before −i) by
    ascending |Im λ| = ω. Sorted by real part first, an elastic pendulum listed ±6.325i before
    ±2.807i beside ω = 2.807, 6.325. Values within rounding of each other count as equal."""
    scale = max(1.0, float(np.max(np.abs(lam)))) if len(lam) else 1.0
    tol = 1e-7 * scale

    def key(i: int) -> tuple:
        z = lam[i]
        omega = abs(z.imag)
        if omega <= tol:
            return (0, 0.0, -round(z.real / tol), 0)
        return (1, round(omega / tol), -round(z.real / tol), 0 if z.imag > 0 else 1)

    return sorted(range(len(lam)), key=key)


def _eigen_sorted(lam: np.ndarray) -> list[complex]:
    return [complex(lam[i]) for i in _eigen_order(lam)]


def _potential(turning: str) -> str:
    if turning == "frame":
        return "effective potential ($V$ with the centrifugal term of the turning frame)"
    if turning:  # a support moved by prescription: no frame turns, no centrifugal term
        return (
            "effective potential ($V$ less $T_0$, the kinetic energy of the prescribed motion "
            "at $\\dot q = 0$)"
        )
    return "potential"


def _semisimple(A: np.ndarray, on_axis: np.ndarray, scale: float) -> bool:
    """Each repeated eigenvalue on the axis has as many eigenvectors as its multiplicity."""
    seen: list[complex] = []
    for z in on_axis:
        if any(abs(z - s) <= 1e-6 * scale for s in seen):
            continue
        seen.append(z)
        multiplicity = int(np.sum(np.abs(on_axis - z) <= 1e-6 * scale))
        if multiplicity == 1:
            continue
        s = np.linalg.svd(A - z * np.eye(len(A)), compute_uv=False)
        if int(np.sum(s <= 1e-6 * scale)) < multiplicity:
            return False
    return True


def _modes(M, C, K, lam, vecs, idx, n):
    """ω from the imaginary parts of the eigenvalues, one per conjugate pair, ascending; modes
    as displacement shapes (max |·| = 1). Without velocity terms and with K symmetric they are
    real (K v = ω² M v); with them a mode may whirl: its amplitudes and each coordinate's phase
    lag are given. A non-symmetric K (a follower load) is taken whole, from the eigenproblem the
    reason quotes: its symmetric part gave a Ziegler column ω = 0.400, 1.530 beside
    λ = ±0.468i, ±1.510i."""
    size = len(idx)
    scale = max(1.0, float(np.max(np.abs(lam)))) if len(lam) else 1.0
    freqs, modes, phases = [], [], []

    def spread(v):
        mode = [0.0] * n
        for j, x in zip(idx, v, strict=True):
            mode[j] = float(x)
        return mode

    k_norm = max(float(np.max(np.abs(K), initial=0.0)), 1e-300)
    if not np.any(C) and np.max(np.abs(K - K.T), initial=0.0) <= 1e-9 * k_norm:
        import scipy.linalg

        w2, vecs_r = scipy.linalg.eigh((K + K.T) / 2, M)
        for i in np.argsort(w2):
            if w2[i] <= 1e-9 * max(1.0, float(np.max(np.abs(w2)))):
                continue
            v = vecs_r[:, i] / np.max(np.abs(vecs_r[:, i]))
            freqs.append(float(math.sqrt(w2[i])))
            modes.append(spread(v))
            phases.append([0.0] * n)
        return freqs, modes, phases
    picked = [i for i in range(len(lam)) if lam[i].imag > 1e-7 * scale]
    for i in sorted(picked, key=lambda i: lam[i].imag):
        v = vecs[:size, i]
        k = int(np.argmax(np.abs(v)))
        v = v * np.conj(v[k]) / abs(v[k]) / abs(v[k])
        standing = np.max(np.abs(v.imag)) <= 1e-6
        freqs.append(float(lam[i].imag))
        if standing:
            modes.append(spread(v.real))
            phases.append([0.0] * n)
        else:
            modes.append(spread(np.abs(v)))
            phases.append(spread(np.where(np.abs(v) > 1e-9, np.angle(v), 0.0)))
    return freqs, modes, phases


def _num(x: float) -> str:
    """x to 4 digits as LaTeX: 1.2 \\cdot 10^{-5}, not the 1.2e-05 that reads as e times 5."""
    text = f"{x:.4g}"
    if "e" not in text:
        return text
    mantissa, exponent = text.split("e")
    return rf"{mantissa} \cdot 10^{{{int(exponent)}}}"


def _z(z: complex) -> str:
    """One eigenvalue, as LaTeX (inside $…$)."""
    if abs(z.imag) <= 1e-12:
        return _num(z.real)
    sign = "-" if z.imag < 0 else "+"
    return f"{_num(z.real)} {sign} {_num(abs(z.imag))}i"


def _eigen_math(lam: np.ndarray) -> str:
    """$λ = …$, each conjugate pair once as a ± b i, and the imaginary-axis ones as ±b i."""
    return rf"$\lambda = {_eigen_text(lam)}$"


def _eigen_text(lam: np.ndarray) -> str:
    """The λ of ``_eigen_math`` as LaTeX, without the $."""
    parts = []
    scale = max(1.0, float(np.max(np.abs(lam)))) if len(lam) else 1.0
    for z in lam:
        if z.imag < -1e-12:
            continue
        if abs(z) <= 1e-9 * scale:
            parts.append("0")  # round-off of a zero eigenvalue: −9.7e-17 said nothing
        elif abs(z.imag) <= 1e-12:
            parts.append(_num(z.real))
        elif abs(z.real) <= 1e-9 * max(1.0, abs(z)):
            parts.append(rf"\pm {_num(z.imag)}i")
        else:
            parts.append(rf"{_num(z.real)} \pm {_num(z.imag)}i")
    return ", ".join(parts)


# --- the stability step ----------------------------------------------------------------------


def _matrix(a: np.ndarray) -> str:
    return to_latex(sp.Matrix(a.shape[0], a.shape[1], [sp.Float(float(x), 5) for x in a.flat]))


def _linear_latex(linear: dict) -> str:
    """M δq̈ + C δq̇ + K δq = 0 with the numbers at this equilibrium and these parameters."""
    qs = linear["coordinates"]
    dq = to_latex(sp.Matrix([sp.Symbol(rf"\delta {to_latex(q)}") for q in qs]))
    dqd = to_latex(sp.Matrix([sp.Symbol(rf"\delta \dot{{{to_latex(q)}}}") for q in qs]))
    dqdd = to_latex(sp.Matrix([sp.Symbol(rf"\delta \ddot{{{to_latex(q)}}}") for q in qs]))
    damping = "" if not np.any(linear["C"]) else f" + {_matrix(linear['C'])}{dqd}"
    return f"{_matrix(linear['M'])}{dqdd}{damping} + {_matrix(linear['K'])}{dq} = 0"


def _latex_text(s: str) -> str:
    return "".join("\\" + c if c in "#$%&_{}^~\\" else c for c in s)


def reason_latex(reason: str) -> str:
    r"""A reason as one LaTeX expression: its words in \text{…}, its $…$ math as math (inside
    \text a caret printed as 'e\^{}(3.1 t)' and a name as 'theta')."""
    parts = reason.split("$")
    if len(parts) % 2 == 0:  # an unpaired $: all of it is words
        return rf"\text{{{_latex_text(reason)}}}"
    return "".join(
        part if k % 2 else rf"\text{{{_latex_text(part)}}}" for k, part in enumerate(parts) if part
    )


#: The macros the reasons use, as plain text (the rest: Greek letters, by their Unicode names).
_PLAIN_MACROS = {
    ",": " ",
    " ": " ",
    "pm": "±",
    "le": "≤",
    "cdot": "·",
    "sum": "Σ",
    "partial": "∂",
    "ell": "ℓ",
    "quad": " ",
    "left": "",
    "right": "",
    "operatorname": "",
    "mathrm": "",
}
#: Unicode's names where TeX's differ (λ is LAMDA there).
_GREEK_SPELLING = {"lambda": "lamda", "varphi": "phi", "vartheta": "theta symbol"}


def _plain_macro(name: str) -> str:
    if name in _PLAIN_MACROS:
        return _PLAIN_MACROS[name]
    spelled = _GREEK_SPELLING.get(name, name)
    try:
        return unicodedata.lookup(f"GREEK SMALL LETTER {spelled.upper()}")
    except KeyError:
        return name


def reason_plain(reason: str) -> str:
    r"""A reason as plain text (the step's copy button): $…$ dropped, \dot x as ẋ, and the
    macros the reasons use as their symbols."""
    text = re.sub(  # every macro but the accents, which then sit on a letter
        r"\\(?!d?dot(?![A-Za-z]))([A-Za-z]+|.)",
        lambda m: _plain_macro(m.group(1)),
        re.sub(r"\\mathbf\s*", "", reason.replace("$", "")),  # bold K is K in plain text
    )
    text = re.sub(
        r"\\(d?dot)\s*\{?([^\s{}\\])\}?",
        lambda m: m.group(2) + ("\u0308" if m.group(1) == "ddot" else "\u0307"),
        text,
    )
    return unicodedata.normalize("NFC", text.replace("{", "").replace("}", ""))


def _stability_step(m: Any, results: list[dict], verdicts: list[Verdict]) -> Step:
    text = (
        rf"About each equilibrium $q_0$ the motion linearizes to {_LINEARIZED} with "
        r"$\mathbf K = -\partial \mathbf f/\partial q$ and "
        r"$\mathbf C = -\partial \mathbf f/\partial \dot q$ at rest ($\mathbf f$ of the matrix "
        r"form $\mathbf M\,\ddot q = \mathbf f$; $\mathbf C$ "
        "holds damping and the gyroscopic terms: Coriolis where a frame turns, forces that do "
        r"no work such as a magnetic one). With $\delta q \propto e^{\lambda t}$ the eigenvalues "
        r"$\lambda$ of the first-order system decide: any $\operatorname{Re}\lambda > 0$ is "
        r"unstable; all $\operatorname{Re}\lambda < 0$ is asymptotically stable; $\mathbf K$ "
        r"symmetric "
        "and positive definite is stable by the potential (Lagrange–Dirichlet) when the "
        f"velocity-dependent forces do no positive work (their power ${_power_symbol(m)}$ is 0 or "
        r"$\le 0$), and undecided when it has no sign; a $\mathbf K$ that is not symmetric "
        "(circulatory forces) has no potential behind it, so only the eigenvalues speak; "
        r"$\mathbf K$ "
        "not positive definite with every $\\lambda$ simple on the imaginary axis is "
        "gyroscopically stable (only linearly: damping destroys it); what the linear test "
        "cannot decide is marginal. The small-oscillation frequencies are the imaginary parts "
        r"$\omega = \operatorname{Im}\lambda$."
    )
    tex = {name: to_latex(q) for name, q in zip(m.coordinate_names, m.q, strict=True)}
    lines = []
    for r, v in zip(results, verdicts, strict=True):
        # a free coordinate is 'any φ', as the panel says it: 'φ = 0' named one of the family
        q = ", ".join(f"any {k}" if k in r["free"] else f"{k} = {x:.4g}" for k, x in r["q"].items())
        q_tex = r",\ ".join(
            rf"\text{{any }}{tex[k]}" if k in r["free"] else f"{tex[k]} = {_num(x)}"
            for k, x in r["q"].items()
        )
        if v.linear is not None:
            linear = v.linear
            lines.append(
                Line(
                    f"linearized about {q}",
                    _linear_latex(linear),
                    f"M = {linear['M'].tolist()}, C = {linear['C'].tolist()}, "
                    f"K = {linear['K'].tolist()}",
                )
            )
        freqs = ", ".join(f"{f:.4g}" for f in v.frequencies)
        omega = rf"\quad \omega = {', '.join(_num(f) for f in v.frequencies)}\ \mathrm{{rad/s}}"
        lines.append(
            Line(
                q,
                rf"{q_tex}:\ \text{{{v.kind}}}{omega if freqs else ''}"
                rf"\\ \text{{because }}{reason_latex(v.reason)}",
                f"{q}: {v.kind} {freqs}".rstrip() + f" — because {reason_plain(v.reason)}",
            )
        )
    return Step("stability", "Stability and small oscillations", text, lines)
