"""Where every term comes from (issue 14, item 2): each term of T, V, Q_j and of each equation of
motion traced to its origins.

The origins are the pieces the energies are built from, split as the derivation's own steps show
them:

* kinetic: per body, ½ m v·v with v = Σ of the velocities of its position's links (a body placed
  ``from`` another is r = r_from + link), each link's velocity written along the unit vectors of
  the frame the link is written in (the kinematics step's frame: ê_r, ê_θ for polar scenes, î, ĵ,
  k̂ for N). A link's own component gives ½ m c² ("the ê_θ component of v"); two different links
  give m v_a·v_b (the double pendulum's coupling). A rigid body adds ½ ω_i I_ij ω_j per pair of
  its body-frame axes.
* potential: each conservative force's share of V, exactly the energy step's ``potential_parts``.
* generalized force: each non-conservative load's virtual work F·∂v/∂q̇_j (the forces step).

An equation's *terms* are the displayed expression's additive pieces, gathered by velocity
monomial (q̈_k, q̇_k q̇_l, …: what tidy() groups by); where one monomial holds several displayed
pieces with different q-dependence they stay separate when every origin splits cleanly between
them. Each origin's contribution to a term is its coefficient of that monomial, so by linearity
the contributions of a term add up to it exactly and the terms add up to the displayed equation
exactly (tests/derivation/test_provenance.py checks both on every built-in scene). In an
equation of motion each origin enters through one of the Euler–Lagrange pieces: d/dt ∂T/∂q̇_j,
−∂T/∂q_j, +∂V/∂q_j (left side) or Q_j (right side); contributions of a monomial that cancel
are listed too.

Term ids are a hash of the term's canonical form, so the same term has the same id in every
equation where it appears and a page can light it up everywhere at once.

Bounded by size, never by the clock (a derivation is a function of its spec): past
`MAX_TERMS` terms, or `MAX_ORIGINS` origins, an equation says it is too large to trace.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field
from typing import Any

import sympy as sp
from sympy.physics.vector import Vector

from mechanics.expr import to_latex, to_plain
from mechanics.spec import FramePosition
from mechanics.steps import _symbols_for, d_dt, partial, tidy
from mechanics.steps.energy import potential_parts

#: An equation with more displayed terms than this is not traced (a textbook prints none).
MAX_TERMS = 200
#: A derivation with more kinetic + potential origins than this is not traced.
MAX_ORIGINS = 400
#: The equations of motion are traced while (2 × shares of T + shares of V) × coordinates, the
#: contributions to differentiate and split, stays within this: a triple pendulum has 114, a
#: four-link chain 280 (2.5 s), a six-link chain about 1500 (8 s, on top of a 13 s derivation
#: whose posted budget is 20 s).
MAX_CONTRIBUTIONS = 600
#: ... and while the same count weighted by each share's size (count_ops) stays within this: the
#: shares of a 3-D system are larger, and a two-link conical pendulum (560 contributions, but
#: 9,856 weighted) took 10 s to trace on top of a 10 s derivation. A triple pendulum weighs 1,212,
#: a heavy top 1,125, a four-link chain 3,040, the built-in scenes at most 352.
MAX_OPS = 3200
#: A contribution larger than this (count_ops) is shown expanded, not tidied: tidying every
#: contribution was two thirds of the time on a six-link chain, and small ones are most of them.
TIDY_OPS = 40

TOO_LARGE = "too many terms to trace"

PIECES = {
    "ddt": "d/dt ∂T/∂q̇",
    "dTdq": "−∂T/∂q",
    "dVdq": "∂V/∂q",
    "Q": "Q",
}


@dataclass
class Origin:
    """One piece an energy or a generalized force is built from (see the module docstring)."""

    id: str
    kind: str  # "kinetic" | "potential" | "generalized force"
    expr: sp.Expr  # function form (q(t)), exact
    meta: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return {"kind": self.kind, **self.meta}

    def brief(self) -> dict[str, Any]:
        """What a source repeats of its origin (the rest is in the response's ``origins``)."""
        out = {"origin": self.id, "kind": self.kind}
        if "body" in self.meta:
            out["body"] = self.meta["body"]
        return out


@dataclass
class Contribution:
    """An origin's share of one equation, before it is split into the equation's terms."""

    origin: Origin
    expr: sp.Expr  # function form
    piece: str | None = None  # a key of PIECES, for equations of motion
    via: str | None = None  # id of the T/V/Q term it came through


# --- canonical forms ---------------------------------------------------------------------------


def _dyn_symbols(model: Any) -> tuple[set, set]:
    """(velocity and acceleration symbols, every symbol that varies: q, q̇, q̈, t), plain."""
    to_sym, _ = _symbols_for(model)
    vel = {to_sym[v] for v in (*model.qd, *model.qdd)}
    dyn = set(to_sym.values()) | {model.names["t"]}
    return vel, dyn


def _plain(expr: sp.Expr, model: Any) -> sp.Expr:
    if isinstance(expr, int) or expr == 0:  # a Vector's dot product may give a Python 0
        return sp.Integer(expr)
    return expr.xreplace(_symbols_for(model)[0])


def _back(expr: sp.Expr, model: Any) -> sp.Expr:
    return expr.xreplace(_symbols_for(model)[1])


@functools.lru_cache(maxsize=8192)
def canonical(expr: sp.Expr) -> sp.Expr:
    """A canonical form for zero tests and ids: trig of sums expanded, cos^n (n ≥ 2) rewritten
    with 1 − sin², expanded. Two forms of a polynomial in sin/cos of independent angles (the
    tidied and the raw) meet here."""
    e = sp.expand(sp.expand_trig(sp.expand(expr)))

    def is_cos_power(p: sp.Expr) -> bool:
        return p.is_Pow and isinstance(p.base, sp.cos) and p.exp.is_Integer and bool(p.exp >= 2)

    for _ in range(8):
        if not e.has(sp.cos):
            break
        new = e.replace(
            is_cos_power,
            lambda p: (1 - sp.sin(p.base.args[0]) ** 2) * sp.cos(p.base.args[0]) ** (p.exp - 2),
        )
        new = sp.expand(new)
        if new == e:
            break
        e = new
    return e


def is_zero(expr: sp.Expr) -> bool:
    """Exactly zero? The canonical form first (fast), then sympy's simplify as a fallback."""
    if expr == 0:
        return True
    c = canonical(expr)
    if c == 0:
        return True
    return sp.simplify(sp.together(c)) == 0


def term_id(expr_plain: sp.Expr) -> str:
    """The same expression, the same id (in every equation of every step)."""
    digest = hashlib.sha1(sp.srepr(canonical(expr_plain)).encode()).hexdigest()[:10]
    return f"pv-{digest}"


def _monomial(piece: sp.Expr, vel: set) -> sp.Expr:
    """The velocity/acceleration monomial of one product: q̇_1 q̇_2, q̈_1, or 1."""
    return sp.Mul(
        *(
            f
            for f in sp.Mul.make_args(piece)
            if f in vel or (f.is_Pow and f.base in vel and f.exp.is_Integer)
        )
    )


def _dependence(piece: sp.Expr, dyn: set) -> sp.Expr:
    """The factors of a product that vary with q, q̇, q̈ or t (parameters and numbers dropped)."""
    return sp.Mul(*(f for f in sp.Mul.make_args(piece) if f.free_symbols & dyn))


def _pieces(expr: sp.Expr, vel: set, dyn: set) -> list[sp.Expr]:
    """A displayed expression as its additive pieces, a factored-out sum distributed only where
    its terms differ (m (ṙ² + r² θ̇²)/2 → two pieces; (m1 + m2) l² θ̈ stays one)."""
    out: list[sp.Expr] = []
    for arg in sp.Add.make_args(expr):
        sums = [f for f in sp.Mul.make_args(arg) if f.is_Add]
        spread = None
        for s in sums:
            keys = {(_monomial(a, vel), _dependence(a, dyn)) for a in s.args}
            if len(keys) > 1:
                spread = s
                break
        if spread is None:
            out.append(arg)
            continue
        rest = sp.Mul(*(f for f in sp.Mul.make_args(arg) if f is not spread))
        out += _pieces(sp.Add(*(rest * a for a in spread.args)), vel, dyn)
    return [p for p in out if p != 0]


def _by_monomial(expr: sp.Expr, vel: set) -> dict[sp.Expr, sp.Expr]:
    """expr (plain) as {velocity monomial: coefficient}, expanded."""
    out: dict[sp.Expr, sp.Expr] = {}
    for arg in sp.Add.make_args(sp.expand(expr)):
        if arg == 0:
            continue
        mono = _monomial(arg, vel)
        out[mono] = out.get(mono, sp.S.Zero) + arg / mono
    return out


def _show(expr: sp.Expr, model: Any) -> sp.Expr:
    """A contribution as the page prints it: tidied when small (function form in and out)."""
    if expr == 0:
        return sp.S.Zero
    if sp.count_ops(expr) <= TIDY_OPS:
        return tidy(expr, model, factor_whole=False)
    return sp.expand(expr)


# --- origins -----------------------------------------------------------------------------------


def _starts(model: Any) -> dict[str, str]:
    """Each point's and body's ``from`` (where its position vector starts): "O" by default."""
    out = {}
    for item in (*model.spec.points, *model.spec.bodies):
        pos = item.position
        out[item.name] = (pos.from_ or "O") if isinstance(pos, FramePosition) else "O"
    return out


def _unit_names(model: Any, frame: str) -> list[tuple[str, str]]:
    """(plain, LaTeX) of a frame's unit vectors, as the kinematics step prints them."""
    plain = model.plain_vectors(frame)
    latex = list(model.frame(frame).latex_vecs)
    return list(zip(plain, latex, strict=True))


def _link_text(end: str, start: str) -> str:
    return f"v of {end}" if start == "O" else f"v of {end} relative to {start}"


def kinetic_origins(model: Any) -> list[Origin]:
    """½ m v·v per body split by link and component, and ½ ω·I·ω by body axes."""
    starts = _starts(model)
    origins: list[Origin] = []
    for b in model.bodies:
        links = []  # (end, start, frame, [(unit plain, unit latex, component)])
        name = b.name
        while name != "O" and len(links) < 64:
            start = starts.get(name, "O")
            frame_name = model.natural[name]
            frame = model.frame(frame_name)
            v = (model.positions[name] - model.positions[start]).dt(model.N)
            comps = [
                (p, lx, v.dot(u))
                for (p, lx), u in zip(
                    _unit_names(model, frame_name), (frame.x, frame.y, frame.z), strict=True
                )
            ]
            comps = [c for c in comps if c[2] != 0]
            if comps:
                links.append((name, start, frame_name, comps))
            name = start
        links.reverse()  # from O outwards, as a reader follows the chain
        m = b.mass
        for i, (end, start, frame_name, comps) in enumerate(links):
            for p, lx, c in comps:
                origins.append(
                    Origin(
                        "",
                        "kinetic",
                        m * c**2 / 2,
                        {
                            "body": b.name,
                            "motion": "translational",
                            "frame": frame_name,
                            "components": [
                                {"link": end, "from": start, "unit": p, "unit_latex": lx}
                            ],
                            "text": f"½ m ({p} component of {_link_text(end, start)})² "
                            f"in T of {b.name}",
                        },
                    )
                )
            for end2, start2, frame2, comps2 in links[i + 1 :]:
                va = sum((c * u for _, _, c, u in _with_units(model, frame_name, comps)), Vector(0))
                vb = sum((c * u for _, _, c, u in _with_units(model, frame2, comps2)), Vector(0))
                dot = va.dot(vb)
                if dot == 0:
                    continue
                origins.append(
                    Origin(
                        "",
                        "kinetic",
                        m * dot,
                        {
                            "body": b.name,
                            "motion": "translational",
                            "frame": frame_name if frame_name == frame2 else None,
                            "components": [
                                {"link": end, "from": start, "frame": frame_name},
                                {"link": end2, "from": start2, "frame": frame2},
                            ],
                            "text": f"m ({_link_text(end, start)})·({_link_text(end2, start2)}) "
                            f"in T of {b.name}: the cross term of v·v",
                        },
                    )
                )
        if b.frame is not None:
            w = b.frame.ang_vel_in(model.N)
            axes = (b.frame.x, b.frame.y, b.frame.z)
            names = _unit_names(model, b.frame.name) if b.frame.name in model.frames else None
            wc = [w.dot(u) for u in axes]
            for i in range(3):
                for j in range(i, 3):
                    inertia_ij = axes[i].dot(b.inertia.dot(axes[j]))
                    piece = (1 if i == j else 2) * wc[i] * inertia_ij * wc[j] / 2
                    if piece == 0:
                        continue
                    axis_names = [
                        names[k][0] if names else f"{b.frame.name}.{'xyz'[k]}" for k in (i, j)
                    ]
                    origins.append(
                        Origin(
                            "",
                            "kinetic",
                            piece,
                            {
                                "body": b.name,
                                "motion": "rotational",
                                "frame": b.frame.name,
                                "components": [{"axis": a} for a in axis_names],
                                "text": f"½ ω·I·ω of {b.name}, "
                                + (
                                    f"the rotation about {axis_names[0]}"
                                    if i == j
                                    else f"the product of inertia of {axis_names[0]} and "
                                    f"{axis_names[1]}"
                                ),
                            },
                        )
                    )
    return origins


def _with_units(model: Any, frame_name: str, comps: list) -> list:
    frame = model.frame(frame_name)
    by_name = dict(zip(model.plain_vectors(frame_name), (frame.x, frame.y, frame.z), strict=True))
    return [(p, lx, c, by_name[p]) for p, lx, c in comps]


def potential_origins(model: Any) -> list[Origin]:
    """Each conservative force's share of V (the energy step's own split)."""
    out = []
    for kind, name, part in potential_parts(model):
        if part == 0:
            continue
        meta: dict[str, Any] = {"source": kind, "name": name}
        if kind == "weight":
            meta["body"] = name
            meta["text"] = f"weight of {name}: m g h"
        elif kind == "spring":
            meta["text"] = f"spring {name}: ½ k (ℓ − ℓ₀)²"
        else:
            meta["text"] = f"the given potential {name}"
        out.append(Origin("", "potential", part, meta))
    return out


def force_origins(model: Any, j: int) -> list[Origin]:
    """Each load's virtual work on q_j: F·∂v/∂q̇_j (torques: M·∂ω/∂q̇_j), as the forces step."""
    qd = model.qd[j]
    out = []
    for load in model.loads:
        if load.kind == "torque":
            body = next(b for b in model.bodies if b.name == load.on)
            part = body.frame.ang_vel_in(model.N).diff(qd, model.N)
        else:
            part = model.velocity(load.on).diff(qd, model.N)
        work = load.vector.dot(part)
        if work == 0:
            continue
        what = "torque" if load.kind == "torque" else load.kind
        out.append(
            Origin(
                "",
                "generalized force",
                work,
                {
                    "source": load.kind,
                    "name": load.name,
                    "body": load.on,
                    "coordinate": model.coordinate_names[j],
                    "text": f"virtual work of the {what} {load.name} on {load.on}",
                },
            )
        )
    return out


def _contribution_ops(t_parts: list, v_parts: list, n: int) -> int:
    """The size-weighted count of contributions to differentiate and split (see MAX_OPS)."""
    t_ops = sum(sp.count_ops(e) for _, _, e in t_parts)
    return int(2 * n * t_ops + n * sum(sp.count_ops(e) for _, _, e in v_parts))


# --- splitting an equation into terms ----------------------------------------------------------


def trace(displayed: sp.Expr, contributions: list[Contribution], model: Any) -> dict[str, Any]:
    """The displayed expression's terms, each with the contributions that make it up.

    Returns {"terms": [...], "cancelled": [...]} or {"traced": False, "reason": ...}. Exact by
    construction: a term's contributions are each origin's coefficient of the term's velocity
    monomial (split further only where the split is exact)."""
    vel, dyn = _dyn_symbols(model)
    shown = _plain(displayed, model)
    pieces = _pieces(shown, vel, dyn)
    if len(pieces) > MAX_TERMS:
        return {"traced": False, "reason": TOO_LARGE, "terms": [], "cancelled": []}
    groups: dict[sp.Expr, list[sp.Expr]] = {}
    for p in pieces:
        groups.setdefault(_monomial(p, vel), []).append(p)
    # Pieces of one monomial that vary alike are one term (l1 m1 cos θ1 + l1 m2 cos θ1).
    for mono, ps in groups.items():
        merged: dict[sp.Expr, list[sp.Expr]] = {}
        for p in ps:
            merged.setdefault(_dependence(p / mono, dyn), []).append(p)
        groups[mono] = [sp.factor_terms(sp.Add(*v)) for v in merged.values()]
    per_contribution = [(c, _by_monomial(_plain(c.expr, model), vel)) for c in contributions]
    terms: list[dict[str, Any]] = []
    for mono, ds in groups.items():
        shares = [(c, by.get(mono, sp.S.Zero)) for c, by in per_contribution]
        shares = [(c, s) for c, s in shares if s != 0]
        split = _split_group(ds, mono, shares, dyn) if len(ds) > 1 else None
        if split is None:
            whole = sp.Add(*ds)
            split = [(whole, [(c, s * mono) for c, s in shares])]
        for d, parts in split:
            term = _term_json(d, parts, model)
            term["_monomial"] = mono  # plain; for the matrix form, dropped from the JSON
            terms.append(term)
    cancelled = []
    # In order of first appearance, never a set's: the JSON must not depend on the hash seed.
    seen = dict.fromkeys(m for _, by in per_contribution for m in by)
    for mono in (m for m in seen if m not in groups):
        parts = [(c, by[mono] * mono) for c, by in per_contribution if by.get(mono, 0) != 0]
        if parts:
            cancelled.append(
                {
                    "monomial_latex": to_latex(_back(mono, model)),
                    "sources": [_source_json(c, e, model) for c, e in parts],
                }
            )
    return {"traced": True, "terms": terms, "cancelled": cancelled}


def _split_group(
    ds: list[sp.Expr], mono: sp.Expr, shares: list, dyn: set
) -> list[tuple[sp.Expr, list]] | None:
    """Split each origin's share of one monomial among several displayed pieces, by the
    canonical q-dependence of their terms; None when the pieces' dependences overlap or an
    origin has a part no piece holds (then the monomial stays one term)."""
    homes: dict[sp.Expr, int] = {}
    for i, d in enumerate(ds):
        for arg in sp.Add.make_args(canonical(d / mono)):
            key = _dependence(arg, dyn)
            if homes.setdefault(key, i) != i:
                return None
    out: list[tuple[sp.Expr, list]] = [(d, []) for d in ds]
    for c, s in shares:
        parts: dict[int, list[sp.Expr]] = {}
        for arg in sp.Add.make_args(canonical(s)):
            if arg == 0:
                continue
            home = homes.get(_dependence(arg, dyn))
            if home is None:
                return None
            parts.setdefault(home, []).append(arg)
        for i, args in parts.items():
            out[i][1].append((c, sp.Add(*args) * mono))
    # Each piece must be exactly its parts (the keys could agree while a coefficient differs,
    # e.g. a share the displayed form cancelled): otherwise keep the monomial whole.
    for d, parts in out:
        if not parts or canonical(d - sp.Add(*(e for _, e in parts))) != 0:
            return None
    return out


def _source_json(c: Contribution, expr_plain: sp.Expr, model: Any) -> dict[str, Any]:
    e = _show(_back(expr_plain, model), model)
    out = c.origin.brief()
    if c.piece is not None:
        out["piece"] = PIECES[c.piece]
    if c.via is not None:
        out["via"] = c.via
    out["contribution_latex"] = to_latex(e)
    out["contribution_plain"] = to_plain(e)
    out["_expr"] = e  # exact; dropped by provenance_json, kept for _through and the tests
    return out


def _term_json(d_plain: sp.Expr, parts: list, model: Any) -> dict[str, Any]:
    d = _back(d_plain, model)
    return {
        "id": term_id(d_plain),
        "latex": to_latex(d),
        "plain": to_plain(d),
        "sources": [_source_json(c, e, model) for c, e in parts],
    }


# --- the whole derivation ----------------------------------------------------------------------


def provenance(derivation: Any) -> dict[str, Any]:
    """Every traced equation of a derivation: T, V, Q_j and each EoM (see the module docstring).

    {"origins": {id: origin}, "T": eq, "V": eq, "Q": {name: eq}, "eom": {name: {"lhs": eq,
    "rhs": eq}}, "matrix": {"M": ..., "f": ...} (see `matrix_form`)}; an eq is {"traced",
    "terms", "cancelled"} (and "reason" when not traced); a term's sources name their origin by
    id (T1…, V1…, Q<j>.<i>), described once in ``origins``."""
    model, work = derivation.model, derivation.work
    kin, pot = kinetic_origins(model), potential_origins(model)
    names = model.coordinate_names
    for i, o in enumerate(kin):
        o.id = f"T{i + 1}"
    for i, o in enumerate(pot):
        o.id = f"V{i + 1}"
    if len(kin) + len(pot) > MAX_ORIGINS:
        skip = {"traced": False, "reason": TOO_LARGE, "terms": [], "cancelled": []}
        return {
            "origins": {},
            "T": skip,
            "V": skip,
            "Q": dict.fromkeys(names, skip),
            "eom": {n: {"lhs": skip, "rhs": skip} for n in names},
            "matrix": {"M": [None] * len(names), "f": [None] * len(names)},
        }
    table = {o.id: o.to_json() for o in (*kin, *pot)}
    T = trace(work.T, [Contribution(o, o.expr) for o in kin], model)
    V = trace(work.V, [Contribution(o, o.expr) for o in pot], model)
    Q: dict[str, Any] = {}
    eom: dict[str, Any] = {}
    t_parts = _through(T, kin, model)
    v_parts = _through(V, pot, model)
    # Every share of T is differentiated twice per coordinate and V's once: past the budget the
    # equations of motion are not traced (T, V and Q_j still are).
    eom_too_large = (2 * len(t_parts) + len(v_parts)) * len(names) > MAX_CONTRIBUTIONS
    eom_too_large = eom_too_large or _contribution_ops(t_parts, v_parts, len(names)) > MAX_OPS
    for j, name in enumerate(names):
        forces = force_origins(model, j)
        for i, o in enumerate(forces):
            o.id = f"Q{j + 1}.{i + 1}"
        table.update((o.id, o.to_json()) for o in forces)
        Q[name] = trace(work.Q[j], [Contribution(o, o.expr) for o in forces], model)
        if eom_too_large:
            skip = {"traced": False, "reason": TOO_LARGE, "terms": [], "cancelled": []}
            eom[name] = {"lhs": skip, "rhs": Q[name]}
            continue
        lhs: list[Contribution] = []
        q, qd = model.q[j], model.qd[j]
        for origin, via, e in t_parts:
            lhs.append(Contribution(origin, d_dt(partial(e, qd, model), model), "ddt", via))
            lhs.append(Contribution(origin, -partial(e, q, model), "dTdq", via))
        for origin, via, e in v_parts:
            lhs.append(Contribution(origin, partial(e, q, model), "dVdq", via))
        lhs = [c for c in lhs if c.expr != 0]
        eom[name] = {
            "lhs": trace(work.eom_lhs[j], lhs, model),
            "rhs": trace(work.Q[j], [Contribution(o, o.expr, "Q") for o in forces], model),
        }
    return {
        "origins": table,
        "T": T,
        "V": V,
        "Q": Q,
        "eom": eom,
        "matrix": matrix_form(eom, model),
    }


def matrix_form(eom: dict[str, Any], model: Any) -> dict[str, Any]:
    """M q̈ = f by term ids: M_jk q̈_k is the sum of EoM j's terms whose monomial is q̈_k, and
    f_j = Σ its right side − Σ its left-side terms free of q̈ (M is linear in q̈ by construction,
    and no EoM term multiplies q̈ by a velocity). None for an equation not traced."""
    to_sym, _ = _symbols_for(model)
    accelerations = [to_sym[a] for a in model.qdd]
    M: list[list[list[str]] | None] = []
    f: list[dict[str, list[str]] | None] = []
    for name in model.coordinate_names:
        lhs, rhs = eom[name]["lhs"], eom[name]["rhs"]
        if not (lhs.get("traced") and rhs.get("traced")):
            M.append(None)
            f.append(None)
            continue
        M.append([[t["id"] for t in lhs["terms"] if t["_monomial"] == a] for a in accelerations])
        f.append(
            {
                "minus": [t["id"] for t in lhs["terms"] if not t["_monomial"].has(*accelerations)],
                "plus": [t["id"] for t in rhs["terms"]],
            }
        )
    return {"M": M, "f": f}


def _through(eq: dict[str, Any], origins: list[Origin], model: Any) -> list[tuple]:
    """(origin, term id, share) for each origin's share of each term of T or V; the origin
    whole when the equation was not traced (the EoM is traced from the origins all the same)."""
    if not eq.get("traced"):
        return [(o, None, o.expr) for o in origins]
    by_id = {o.id: o for o in origins}
    out = []
    for term in eq["terms"]:
        for s in term["sources"]:
            out.append((by_id[s["origin"]], term["id"], s["_expr"]))
    for c in eq["cancelled"]:
        for s in c["sources"]:
            out.append((by_id[s["origin"]], None, s["_expr"]))
    return out


def provenance_json(derivation: Any) -> dict[str, Any]:
    """`provenance` as the derive response carries it (JSON only: the exact sympy forms of the
    contributions, kept in memory for tracing, are dropped)."""
    return _strip(provenance(derivation))


def _strip(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _strip(v) for k, v in value.items() if k not in ("_expr", "_monomial")}
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value
