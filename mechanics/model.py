"""Scene spec -> sympy.physics.vector frames, points, bodies and the forces on them.

The model is the one place where text becomes algebra: every expression of the spec goes through
the whitelist parser with the field path it came from, so a bad name is reported where it sits.
Nothing here differentiates energies; the steps do that from the model.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.physics.mechanics import Particle, RigidBody, inertia
from sympy.physics.vector import Point, ReferenceFrame, Vector, dynamicsymbols

from mechanics.expr import parse, to_plain
from mechanics.spec import FramePosition, SceneSpec, parse_spec
from mechanics.spec_names import nonnegative_parameters

T = dynamicsymbols._t

#: Unit vectors of the inertial frame N, as the notes write the fixed basis {i, j, k}.
N_LATEX = (r"\hat{\imath}", r"\hat{\jmath}", r"\hat{k}")
N_PLAIN = ("i", "j", "k")


@dataclass
class FrameInfo:
    name: str
    frame: ReferenceFrame
    parent: str
    axis: str
    angle: sp.Expr
    plain_vectors: tuple[str, str, str]


@dataclass
class BodyInfo:
    name: str
    kind: str
    mass: sp.Expr
    point: Point
    position: Vector  # from O
    natural_frame: str  # the frame its position was written in
    frame: ReferenceFrame | None = None
    inertia: Any = None  # dyadic about the centre of mass
    sympy_body: Any = None


@dataclass
class Load:
    """A non-conservative force (or torque) and where it acts; enters Q_j through virtual work."""

    name: str
    kind: str  # "force" | "damper" | "torque"
    on: str
    vector: Vector
    natural_frame: str = "N"


@dataclass
class SpringInfo:
    name: str
    a: str
    b: str
    k: sp.Expr
    rest_length: sp.Expr
    length: sp.Expr
    energy: sp.Expr
    #: ℓ written without |·| on one side of the anchor (`length` = `branch` there, valid while it
    #: is > 0); None when ℓ needs no branch (ℓ₀ = 0, a sign fixed by assumptions, or ℓ = √(d·d)).
    branch: sp.Expr | None = None
    sign: int = 0  # which side: ℓ = sign · p for the perfect square d·d = p²


@dataclass
class StopInfo:
    """A condition past which the model does not hold (see `mechanics.spec.Stop`): the run ends
    where `when` (or the named body's tension) reaches 0."""

    name: str
    message: str
    when: sp.Expr | None = None
    tension: str | None = None
    crossing: str = "falls"
    only_if: sp.Expr | None = None
    along: tuple[float, float, float] | None = None  # unit vector in N: the string's direction
    #: "declared", or an implicit one: "anchor", "positive", "domain" (a position's domain end,
    #: approached tangentially when the mass matrix blows up there: x = l√θ at θ = 0).
    kind: str = "declared"


@dataclass
class Model:
    spec: SceneSpec
    q: list[sp.Expr]
    qd: list[sp.Expr]
    qdd: list[sp.Expr]
    params: dict[str, sp.Symbol]
    names: dict[str, sp.Expr]
    N: ReferenceFrame
    O: Point  # noqa: E741
    frames: dict[str, FrameInfo]
    positions: dict[str, Vector]
    natural: dict[str, str]
    points: dict[str, Point]
    bodies: list[BodyInfo]
    gravity: tuple[sp.Expr, Vector] | None
    springs: list[SpringInfo] = field(default_factory=list)
    loads: list[Load] = field(default_factory=list)
    potentials: list[tuple[str, sp.Expr]] = field(default_factory=list)
    #: The sides of its anchor each branched spring was derived for ({index: ±1}).
    branches: dict[int, int] = field(default_factory=dict)
    #: Declared stops, then the implicit ones: a branched spring reaching its anchor, a positive
    #: coordinate reaching 0.
    stops: list[StopInfo] = field(default_factory=list)
    #: Quantities a real system cannot have negative, as written (field path, what it is, value):
    #: checked at the parameter values of every run by `physical_limit_errors`.
    limits: list[tuple[str, str, Any]] = field(default_factory=list)

    @property
    def coordinate_names(self) -> list[str]:
        return list(self.spec.coordinates)

    def velocity(self, place: str) -> Vector:
        return self.positions[place].dt(self.N)

    def frame(self, name: str) -> ReferenceFrame:
        return self.N if name == "N" else self.frames[name].frame

    def plain_vectors(self, name: str) -> tuple[str, str, str]:
        return N_PLAIN if name == "N" else self.frames[name].plain_vectors


def symbols_for(spec: SceneSpec) -> tuple[list, dict[str, sp.Symbol], dict[str, sp.Expr]]:
    """Coordinates as functions of t, parameters as symbols, and the parser's name table.

    Only parameters nonnegative by nature (a mass, a length, a stiffness: `nonnegative_parameters`)
    are declared nonnegative, so that sqrt(l**2) prints as l; every request refuses negative values
    for exactly those. Everything else is merely real: a charge or a rotation rate may be negative.
    """
    positive = set(spec.positive_coordinates)
    magnitudes = nonnegative_parameters(spec)
    q = [
        dynamicsymbols(name, positive=True) if name in positive else dynamicsymbols(name)
        for name in spec.coordinates
    ]
    params = {
        name: sp.Symbol(name, nonnegative=True)
        if name in magnitudes
        else sp.Symbol(name, real=True)
        for name in spec.parameters
    }
    names: dict[str, sp.Expr] = {"t": T, **params}
    for name, qi in zip(spec.coordinates, q, strict=True):
        names[name] = qi
        names[f"{name}_dot"] = qi.diff(T)
        names[f"{name}_ddot"] = qi.diff(T, 2)
    return q, params, names


def _frame_latex(name: str, unit_vectors: list[str] | None) -> tuple[list[str], tuple]:
    if unit_vectors:
        latex = []
        for u in unit_vectors:
            base, _, sub = u.partition("_")
            sub_latex = sp.latex(sp.Symbol(sub)) if sub else ""
            latex.append(rf"\hat{{{base}}}_{{{sub_latex}}}" if sub else rf"\hat{{{base}}}")
        return latex, tuple(unit_vectors)
    low = name.lower()
    return [rf"\hat{{{low}}}_{{{a}}}" for a in "xyz"], tuple(f"{name}.{a}" for a in "xyz")


def build_model(spec: SceneSpec | dict, branches: dict[int, int] | None = None) -> Model:
    """Turn a validated spec into frames, points and bodies; raises ExprError with field paths.

    ``branches`` picks, per spring index, the side of its anchor a spring along a line is on
    (ℓ = ±p); by default the side of the spec's initial state. A run that starts on the other
    side is derived with the other sign, so V = ½k(|d| − ℓ₀)² holds for every state.
    """
    if not isinstance(spec, SceneSpec):
        spec = parse_spec(spec)
    q, params, names = symbols_for(spec)
    # Accelerations never appear in a scene's geometry or forces.
    names = {k: v for k, v in names.items() if not k.endswith("_ddot")}
    N = ReferenceFrame("N", latexs=list(N_LATEX))
    O = Point("O")  # noqa: E741 — the notes' name for the origin
    O.set_vel(N, 0)

    def expr(value: Any, where: str, allow_velocity: bool = False, smooth: bool = False) -> sp.Expr:
        """``smooth``: the expression is differentiated in time (a position, a frame's angle),
        so abs() or sign() of a coordinate in it is refused with its field (its derivative
        stays unevaluated and every later step would fail); a force may hold sign(s_dot)."""
        table = names if allow_velocity else {k: v for k, v in names.items() if "_dot" not in k}
        out = parse(value, table, field=where, smooth=smooth)
        if smooth:
            _refuse_root_of_square(out, where)
            differentiated.append((where, out))
        return out

    #: Every expression differentiated in time, with its field: their domains end where a root
    #: or a logarithm of a coordinate-dependent argument does (implicit stops, below).
    differentiated: list[tuple[str, sp.Expr]] = []

    frames: dict[str, FrameInfo] = {}
    for i, f in enumerate(spec.frames):
        parent = N if f.parent == "N" else frames[f.parent].frame
        angle = expr(f.angle, f"frames[{i}].angle", smooth=True)
        latex, plain = _frame_latex(f.name, f.unit_vectors)
        frame = ReferenceFrame(f.name, latexs=latex)
        frame.orient_axis(parent, getattr(parent, f.axis), angle)
        frames[f.name] = FrameInfo(f.name, frame, f.parent, f.axis, angle, plain)

    def frame_of(name: str) -> ReferenceFrame:
        return N if name == "N" else frames[name].frame

    positions: dict[str, Vector] = {"O": Vector(0)}
    natural: dict[str, str] = {"O": "N"}

    def vector(
        pos: Any, where: str, allow_velocity: bool = False, smooth: bool = False
    ) -> tuple[Vector, str, str]:
        """A position-like field -> (vector, frame it is written in, the place it starts from)."""
        if isinstance(pos, FramePosition):
            comps, frame_name, start = pos.components, pos.frame, pos.from_ or "O"
            path = f"{where}.components"
        else:
            comps, frame_name, start = pos, "N", "O"
            path = where
        fr = frame_of(frame_name)
        v = Vector(0)
        for j, c in enumerate(comps):
            v += expr(c, f"{path}[{j}]", allow_velocity, smooth) * getattr(fr, "xyz"[j])
        return v, frame_name, start

    def place(pos: Any, where: str) -> tuple[Vector, str]:
        v, frame_name, start = vector(pos, where, smooth=True)
        if start not in positions:
            # A body may hang from a body declared later; resolve in declaration order instead.
            raise _Unresolved(start)
        return positions[start] + v, frame_name

    pending = [("points", i, p) for i, p in enumerate(spec.points)]
    pending += [("bodies", i, b) for i, b in enumerate(spec.bodies)]
    for _ in range(len(pending) + 1):
        waiting = []
        for group, i, item in pending:
            try:
                positions[item.name], natural[item.name] = place(
                    item.position, f"{group}[{i}].position"
                )
            except _Unresolved:
                waiting.append((group, i, item))
        if not waiting:
            break
        if len(waiting) == len(pending):
            from mechanics.spec import SpecError

            raise SpecError(
                [
                    {"field": f"{g}[{i}].position.from", "message": "positions refer in a circle"}
                    for g, i, _ in waiting
                ]
            )
        pending = waiting

    points: dict[str, Point] = {"O": O}
    for name, r in positions.items():
        if name != "O":
            P = O.locatenew(name, r)
            P.set_vel(N, r.dt(N))
            points[name] = P

    limits: list[tuple[str, str, Any]] = []
    bodies: list[BodyInfo] = []
    for i, b in enumerate(spec.bodies):
        mass = expr(b.mass, f"bodies[{i}].mass")
        limits.append((f"bodies[{i}].mass", f"{b.name}'s mass", mass))
        info = BodyInfo(b.name, b.kind, mass, points[b.name], positions[b.name], natural[b.name])
        if b.kind == "rigid_body":
            fr = frame_of(b.frame)
            inert = {
                key: expr(getattr(b.inertia, key), f"bodies[{i}].inertia.{key}")
                for key in ("ixx", "iyy", "izz", "ixy", "iyz", "izx")
            }
            dyadic = inertia(
                fr,
                inert["ixx"],
                inert["iyy"],
                inert["izz"],
                inert["ixy"],
                inert["iyz"],
                inert["izx"],
            )
            info.frame, info.inertia = fr, dyadic
            limits.append((f"bodies[{i}].inertia", f"{b.name}'s inertia", inert))
            info.sympy_body = RigidBody(b.name, points[b.name], fr, mass, (dyadic, points[b.name]))
        else:
            info.sympy_body = Particle(b.name, points[b.name], mass)
        bodies.append(info)

    gravity = None
    if spec.gravity is not None:
        g = expr(spec.gravity.acceleration, "gravity.acceleration")
        limits.append(("gravity.acceleration", "the magnitude of gravity", g))
        d = [sp.nsimplify(c) for c in spec.gravity.direction] + [0] * (
            3 - len(spec.gravity.direction)
        )
        norm = sp.sqrt(sum(c**2 for c in d))
        gravity = (
            g,
            sum((c / norm * u for c, u in zip(d, (N.x, N.y, N.z), strict=True)), Vector(0)),
        )

    springs = []
    chosen: dict[int, int] = {}
    for i, s in enumerate(spec.springs):
        k = expr(s.k, f"springs[{i}].k")
        l0 = expr(s.rest_length, f"springs[{i}].rest_length")
        d = positions[s.b] - positions[s.a]
        name = s.name or f"spring{i + 1}"
        limits.append((f"springs[{i}].k", f"the stiffness of {name}", k))
        limits.append((f"springs[{i}].rest_length", f"the rest length of {name}", l0))
        _has_length(d, f"springs[{i}].b")
        if l0.is_zero:  # ½ k d·d: smooth everywhere, no length to take a root of
            length, branch, sign = _length_of(d.dot(d))
            springs.append(SpringInfo(name, s.a, s.b, k, l0, length, k * d.dot(d) / 2))
            continue
        length, branch, sign = _length_of(d.dot(d), (branches or {}).get(i), spec, names)
        if branch is not None:
            chosen[i] = sign
        energy = k * (length - l0) ** 2 / 2
        springs.append(SpringInfo(name, s.a, s.b, k, l0, length, energy, branch, sign))

    loads: list[Load] = []
    for i, dmp in enumerate(spec.dampers):
        # A dashpot resists only the rate its length changes: F_b = −c ((v_b − v_a)·ê) ê, with
        # ê d·d = (d·ê) d, so no square root (and no direction to lose at zero length on a line).
        c = expr(dmp.c, f"dampers[{i}].c")
        d = positions[dmp.b] - positions[dmp.a]
        _has_length(d, f"dampers[{i}].b")
        rel = positions[dmp.b].dt(N) - positions[dmp.a].dt(N)
        along = -c * rel.dot(d) / _tidy_square(d.dot(d)) * d
        name = dmp.name or f"damper{i + 1}"
        limits.append((f"dampers[{i}].c", f"the damping coefficient of {name}", c))
        loads.append(Load(name, "damper", dmp.b, along))
        if dmp.a != "O":
            loads.append(Load(name, "damper", dmp.a, -along))
    for group, kind, items in (
        ("forces", "force", spec.forces),
        ("torques", "torque", spec.torques),
    ):
        for i, f in enumerate(items):
            v, frame_name, _ = vector(f.vector, f"{group}[{i}].vector", allow_velocity=True)
            loads.append(Load(f.name or f"{kind[0].upper()}{i + 1}", kind, f.on, v, frame_name))

    potentials = [
        (p.name, expr(p.expression, f"potentials[{i}].expression"))
        for i, p in enumerate(spec.potentials)
    ]
    stops = [
        StopInfo(
            st.name,
            st.message,
            None if st.when is None else _stop_value(expr, st, i, names),
            st.tension,
            st.crossing,
            None
            if st.only_if is None
            else expr(st.only_if, f"stops[{i}].only_if", allow_velocity=True),
            _unit(st.along),
        )
        for i, st in enumerate(spec.stops)
    ]
    for s in springs:
        if s.branch is not None:
            stops.append(
                StopInfo(
                    f"{s.name}_at_anchor",
                    f"the spring {s.name} reaches zero length: its direction is undefined "
                    "there (V = ½k(|d| − ℓ₀)² has a corner), so the model ends",
                    _corner_only_if_stretched(s.branch, s.rest_length),
                    kind="anchor",
                )
            )
    stops += _anchor_stops_at_run_values(springs, positions, N, q)
    stops += _domain_stops(differentiated, spec, names)
    for name, qi in zip(spec.coordinates, q, strict=True):
        if name in spec.positive_coordinates:
            stops.append(
                StopInfo(
                    f"{name}_at_zero",
                    f"{name} reaches 0: it is declared positive, and the equations were "
                    f"derived for {name} > 0 only",
                    qi,
                    kind="positive",
                )
            )
    model = Model(
        spec=spec,
        q=q,
        qd=[qi.diff(T) for qi in q],
        qdd=[qi.diff(T, 2) for qi in q],
        params=params,
        names=names,
        N=N,
        O=O,
        frames=frames,
        positions=positions,
        natural=natural,
        points=points,
        bodies=bodies,
        gravity=gravity,
        springs=springs,
        loads=loads,
        potentials=potentials,
        branches=chosen,
        stops=stops,
        limits=limits,
    )
    from mechanics.spec import SpecError

    errors = physical_limit_errors(model, spec.parameters)
    if errors:
        raise SpecError(errors)
    return model


#: Relative size below which a negative principal moment or a triangle-inequality excess is
#: rounding (m l²/12 written as a decimal), not a wrong inertia.
INERTIA_ROUNDING = 1e-9


def _start_numbers(model: Model, initial: dict[str, float] | None) -> dict[Any, Any]:
    """t = 0 and the initial state (q, q̇), as a substitution for a limit written in them."""
    init = {**model.spec.initial, **(initial or {})}
    numbers: dict[Any, Any] = {T: sp.Float(0)}
    for name, qi, vi in zip(model.coordinate_names, model.q, model.qd, strict=True):
        numbers[vi] = sp.Float(init.get(f"{name}_dot", 0.0))
        numbers[qi] = sp.Float(init.get(name, 0.0))
    return numbers


def _moves(value: Any, model: Model) -> bool:
    """Whether a limit's expression depends on t or the state (checked along the run too)."""
    return isinstance(value, sp.Basic) and value.has(T, *model.q)


def physical_limit_errors(
    model: Model, values: dict[str, float], initial: dict[str, float] | None = None
) -> list[dict[str, str]]:
    """What no real system has, at these parameter values, each naming its field.

    The per-parameter sign checks see only a parameter standing alone (k = "k"); written as a
    number or an expression ("-5", "k - 3", "-k") a negative stiffness, damping coefficient,
    rest length or gravity went through and the run pumped energy in with no warning, and a
    negative mass ("m - 2" at m = 1) was blamed on the initial state. A central
    inertia tensor must be positive semidefinite with principal moments obeying the triangle
    inequality (I₁ + I₂ ≥ I₃: ∫(x² + y²) dm ≤ ∫(y² + z²) dm + ∫(z² + x²) dm). A value that
    depends on the state or on t ("k*(x - 1)", "m*(t - 2)") is taken at the run's start, t = 0
    and the initial state (the spec's, with ``initial`` over it), and along the run by
    `limits_along_run`.
    """
    numbers = {model.params[k]: sp.Float(v) for k, v in values.items() if k in model.params}
    start = _start_numbers(model, initial)
    errors: list[dict[str, str]] = []

    def number(e: Any) -> float | None:
        try:
            return float(e.xreplace(numbers).xreplace(start))
        except (TypeError, ValueError):
            return None

    for where, what, value in model.limits:
        entries = value.values() if isinstance(value, dict) else [value]
        at = " at t = 0 s and the initial state" if any(_moves(v, model) for v in entries) else ""
        if isinstance(value, dict):
            entries = {k: number(v) for k, v in value.items()}
            errors += _inertia_errors(where, what + at, entries)
            continue
        x = number(value)
        # a mass of 0 in the parameters is the mass matrix's to refuse (it names the coordinate
        # left without inertia); one that is 0 at the start only (m (θ − 2) at θ0 = 2) is this
        zero_here = x == 0 and bool(at) and where.endswith(".mass")
        if x is None or (x >= 0 and not zero_here):
            continue
        alone = str(value) if value in model.params.values() else None
        hint = (
            ": point gravity.direction the other way for gravity pointing up"
            if where == "gravity.acceleration"
            else ""
        )
        shown = "" if alone or value.is_number else f" ({to_plain(value)} at these parameters{at})"
        # a mass of 0 is the mass matrix's to refuse (it names the coordinate left without
        # inertia); a negative one is no body at all
        bound = "> 0" if where.endswith(".mass") else "≥ 0"
        errors.append(
            {
                "field": f"parameters.{alone}" if alone else where,
                "message": f"must be {bound}: {what} is {x:g}{shown}{hint}",
            }
        )
    return errors


@lru_cache(maxsize=256)
def _along(value: sp.Expr, q: tuple, qd: tuple, params: tuple) -> Any:
    """value as a numpy function of (t, q, q̇, parameters), each an array over the samples."""
    t, qs, vs = sp.Dummy("t"), [sp.Dummy() for _ in q], [sp.Dummy() for _ in qd]
    plain = value.xreplace(dict(zip(qd, vs, strict=True))).xreplace(
        {T: t, **dict(zip(q, qs, strict=True))}
    )
    return sp.lambdify((t, qs, vs, list(params)), plain, "numpy")


def limits_along_run(
    model: Model, values: dict[str, float], t: np.ndarray, q: np.ndarray, qd: np.ndarray
) -> list[str]:
    """A warning for each limit written in t or the state that a run's samples carry below 0.

    The start is refused by `physical_limit_errors`; past it a stiffness "k*(x - 1)" or an
    inertia "a*cos(t)" may still turn negative, and the run goes on integrating equations of
    no real system (the physical pendulum with izz = cos t reached M = 0 at t = 1.823 s and was
    told as a blow-up 'fed by a force'). Named by field and time, so the cause is the one seen.
    """
    names = list(model.params)
    args = (tuple(model.q), tuple(model.qd), tuple(model.params[k] for k in names))
    p = [np.full(len(t), float(values[k])) for k in names]
    warnings: list[str] = []

    def along(e: Any) -> np.ndarray:
        out = _along(e, *args)(t, list(q), list(qd), p)
        return np.broadcast_to(np.asarray(out, dtype=float), t.shape)

    for where, what, value in model.limits:
        entries = value if isinstance(value, dict) else {"": value}
        if not any(_moves(v, model) for v in entries.values()):
            continue
        with np.errstate(all="ignore"):
            try:
                series = {k: along(v) for k, v in entries.items()}
            except (TypeError, ValueError, ZeroDivisionError):
                continue
        if isinstance(value, dict):
            bad = [(k, series[k]) for k in ("ixx", "iyy", "izz") if _moves(value[k], model)]
            rows = (("ixx", "ixy", "izx"), ("ixy", "iyy", "iyz"), ("izx", "iyz", "izz"))
            tensors = np.stack([np.stack([series[k] for k in row], -1) for row in rows], -2)
            ok = np.all(np.isfinite(tensors), axis=(-2, -1))
            low = np.full(len(t), np.inf)
            low[ok] = np.linalg.eigvalsh(tensors[ok])[:, 0]
            high = np.abs(tensors).max(axis=(-2, -1))
            bad.append(("", np.where(low < -INERTIA_ROUNDING * high, -1.0, 1.0)))
        else:
            bad = [("", series[""])]
        for key, x in bad:
            strict = where.endswith(".mass")
            # a mass reaching 0 ends the motion's description as surely as a negative one;
            # to rounding of its start (m (1 − t/2) at a failed step 1e-9 s short of t = 2)
            zero = 1e-6 * abs(float(x[0])) if strict and np.isfinite(x[0]) else 0.0
            hit = np.nonzero(x <= zero if strict else x < 0)[0]
            if not len(hit):
                continue
            i = int(hit[0])
            field = f"{where}.{key}" if key else where
            one = value[key] if key else None if isinstance(value, dict) else value
            shown = to_plain(one) if one is not None else None
            if shown is None:
                warnings.append(
                    f"{field} ({what}) is not positive semidefinite by t = {t[i]:.3g} s: no "
                    "mass distribution has such a tensor, so the run from there on is not the "
                    "motion of a real body."
                )
                break
            said = f"{field} = {shown}"
            state = "negative" if x[i] < 0 else "0"
            warnings.append(
                f"{said} is {state} by t = {t[i]:.3g} s ({x[i]:.3g} there): no real system has "
                f"{what} {'below' if state == 'negative' else 'at'} 0, so the run from there on "
                "is not the motion of one."
            )
            break
    return warnings


def _inertia_errors(where: str, what: str, entries: dict[str, float | None]) -> list[dict]:
    """A central inertia tensor no mass distribution has: a negative moment (named by its entry),
    a tensor that is not positive semidefinite, or principal moments breaking I₁ + I₂ ≥ I₃."""
    if any(v is None for v in entries.values()):
        return []
    negative = [k for k in ("ixx", "iyy", "izz") if entries[k] < 0]
    if negative:
        return [
            {
                "field": f"{where}.{k}",
                "message": f"must be ≥ 0: a moment of inertia is "
                f"∫ r² dm, and {what} has {k} = {entries[k]:g}",
            }
            for k in negative
        ]
    e = entries
    rows = (("ixx", "ixy", "izx"), ("ixy", "iyy", "iyz"), ("izx", "iyz", "izz"))
    tensor = np.array([[e[k] for k in row] for row in rows])
    if not np.all(np.isfinite(tensor)):
        return []
    low, mid, high = np.linalg.eigvalsh(tensor)
    tol = INERTIA_ROUNDING * max(abs(high), 1e-300)
    moments = ", ".join(f"{x:.4g}" for x in (low, mid, high))
    if low < -tol:
        return [
            {
                "field": where,
                "message": f"{what} is not positive semidefinite: its principal moments are "
                f"{moments}, and a moment of inertia about any axis is ∫ r² dm ≥ 0 (the "
                "products ixy, iyz, izx are too large for the moments on the diagonal)",
            }
        ]
    if high > low + mid + tol:
        return [
            {
                "field": where,
                "message": f"{what} has principal moments {moments}: no mass distribution has "
                "these, since the largest may not exceed the sum of the other two "
                "(I₁ + I₂ ≥ I₃; a thin rod or a flat disk reaches equality)",
            }
        ]
    return []


def _anchor_stops_at_run_values(
    springs: list[SpringInfo], positions: dict[str, Vector], N: ReferenceFrame, q: list
) -> list[StopInfo]:
    """The anchor stop of a spring that is along a line only at some parameter values: d = (x, h)
    is no perfect square, so no branch stop was made, yet at h = 0 the run's ℓ = |x| reaches 0,
    where V has the same corner. One stop per component d_i that moves: its sign change, where
    every other component is exactly 0 (the guard −Σ d_j² ≥ 0), is ℓ reaching 0. A body passing
    near the anchor but not through it (d_j ≠ 0) does not stop; one moving on the line does.
    """
    out = []
    for s in springs:
        rooted = any(p.exp == sp.S.Half for p in s.length.atoms(sp.Pow))
        if s.branch is not None or s.rest_length.is_zero or not rooted:
            continue  # along a line in the spec itself (a branch stop), smooth, or never 0
        d = positions[s.b] - positions[s.a]
        parts = [sp.expand(d.dot(u)) for u in (N.x, N.y, N.z)]
        parts = [c for c in parts if c != 0]
        if any(c.is_number for c in parts):
            continue  # a constant nonzero offset: ℓ never reaches 0
        for i, c in enumerate(parts):
            if not c.has(T, *q):
                continue
            others = sum((o**2 for j, o in enumerate(parts) if j != i), sp.S.Zero)
            out.append(
                StopInfo(
                    f"{s.name}_at_anchor",
                    f"the spring {s.name} reaches zero length: its direction is undefined "
                    "there (V = ½k(|d| − ℓ₀)² has a corner), so the model ends",
                    _corner_only_if_stretched(c, s.rest_length),
                    crossing="any",
                    only_if=-others,
                    kind="anchor",
                )
            )
    return out


def _corner_only_if_stretched(branch: sp.Expr, rest_length: sp.Expr) -> sp.Expr:
    """The anchor stop's value: the branch p while ℓ₀ ≠ 0, a constant 1 (never reached) when ℓ₀
    is 0 in the run's parameters.

    V = ½k(|p| − ℓ₀)² has a corner at p = 0 only for ℓ₀ ≠ 0: with ℓ₀ = 0 it is ½k p², smooth,
    and the equations derived on either side (ℓ = ±p) are the same, −k p ∂p/∂q, so a body passes
    straight through the anchor (an isotropic oscillator through its centre). A rest length that
    is a parameter is only known at run time, hence the Piecewise rather than a choice here.
    """
    if rest_length.is_zero is False:
        return branch
    return sp.Piecewise((branch, sp.Ne(rest_length, 0)), (sp.S.One, True))


def _real_twins(expr: sp.Expr, names: dict[str, sp.Expr]) -> sp.Expr:
    """expr with q(t), q̇(t) and t as plain real symbols (velocities first: q̇ holds q), so
    sympy's assumptions can decide its sign for every real state. Coordinates declared positive
    become merely real: a stop is there to catch them leaving their domain."""
    out = expr
    for name, value in sorted(names.items(), key=lambda kv: -kv[0].count("_dot")):
        if not isinstance(value, sp.Symbol):  # parameters keep their assumptions (≥ 0 only
            out = out.xreplace({value: sp.Dummy(name, real=True)})  # where requests enforce it)
    return out.xreplace({T: sp.Dummy("t", real=True)})  # last: q(t) holds t


def _stop_value(expr: Any, st: Any, i: int, names: dict[str, sp.Expr]) -> sp.Expr:
    """A declared stop's `when`, refused (naming the field) when it cannot change sign.

    A run stops where `when` crosses 0, seen as a change of sign between steps. A function that
    is never negative (θ², 1 + θ²) can only touch 0 and a run cannot see it do so (a sampled
    minimum is never exactly 0): it used to be silently ignored. We refuse it instead of guessing
    at touches, which would also fire near every close approach; a stop that changes sign where
    the model ends (θ, not θ²) is what to write.
    """
    where = f"stops[{i}].when"
    value = expr(st.when, where, allow_velocity=True)
    real = _real_twins(value, names)
    from mechanics.spec import SpecError

    def refuse(message: str) -> SpecError:
        return SpecError([{"field": where, "message": message}])

    if value == 0:  # 0 for good: no crossing to find, and no state past it (never reported)
        return value
    if real.is_positive or real.is_negative:
        sign = "positive" if real.is_positive else "negative"
        raise refuse(
            f"{to_plain(value)} is {sign} in every state, so it never reaches 0 and the stop "
            "could never fire: give an expression that is positive while the model holds and "
            "changes sign where it ends"
        )
    if real.is_nonnegative or real.is_nonpositive:
        raise refuse(
            f"{to_plain(value)} never changes sign (it only touches 0), and a run finds a stop "
            "where its expression changes sign: give one that does where the model ends "
            "(e.g. theta rather than theta**2)"
        )
    return value


_ROOTS = "a square root (or a fractional power) of a negative number"


def _domain_ends(value: sp.Expr) -> list[tuple[sp.Expr, str]]:
    """What must stay > 0 for ``value`` to be a real number: the argument of each root, each
    logarithm, and 1 − x² of each asin/acos, where it depends on a coordinate or t (with why)."""
    out = []
    for node in sp.preorder_traversal(value):
        if isinstance(node, sp.Pow) and _fractional(node.exp):
            end, why = node.base, _ROOTS
        elif isinstance(node, sp.log):
            end, why = node.args[0], "the logarithm of a number ≤ 0"
        elif isinstance(node, sp.asin | sp.acos):
            end, why = 1 - node.args[0] ** 2, f"{node.func.__name__} of a number outside [−1, 1]"
        else:
            continue
        if end.has(AppliedUndef, T) and all(end != e for e, _ in out):
            out.append((end, why))
    return out


def _fractional(exponent: sp.Expr) -> bool:
    return exponent.is_number and exponent.is_integer is False


def _domain_stops(
    differentiated: list[tuple[str, sp.Expr]], spec: SceneSpec, names: dict[str, sp.Expr]
) -> list[StopInfo]:
    """An implicit stop where a position (or a frame's angle) reaches the end of its domain.

    x = l√θ has no value past θ = 0: the equations may run on there, finite (they were derived
    for θ > 0), and the run used to be flagged only by its energy drift. The stop ends it at
    θ = 0 instead, located like any stop. An argument positive in every real state (1 + θ²)
    has no end and gets no stop.
    """
    stops: list[StopInfo] = []
    seen: list[sp.Expr] = []
    for where, value in differentiated:
        for end, why in _domain_ends(value):
            if any(end == e for e in seen) or _real_twins(end, names).is_positive:
                continue
            seen.append(end)
            what = _what_is_at(where, spec)
            stops.append(
                StopInfo(
                    f"{what[1]}_domain_end" + (f"{len(seen)}" if len(seen) > 1 else ""),
                    f"{what[0]} is undefined past {to_plain(end)} = 0 ({where} would take "
                    f"{why}): the state would have left the domain of its position function, "
                    "so the model ends there",
                    end,
                    kind="domain",
                )
            )
    return stops


def _what_is_at(where: str, spec: SceneSpec) -> tuple[str, str]:
    """'bodies[1].position[0]' -> ('the position of bob', 'bob')."""
    group, _, rest = where.partition("[")
    index = int(rest.split("]", 1)[0])
    item = getattr(spec, group)[index]
    if group == "frames":
        return f"the angle of frame {item.name}", item.name
    return f"the position of {item.name}", item.name


def _refuse_root_of_square(value: sp.Expr, where: str) -> None:
    """√(f²) is |f|: refused in an expression differentiated in time, as abs() is (by the parser).

    |sin θ| written as sqrt(sin(theta)**2) has a kink where sin θ = 0, and its derivative
    f f'/√(f²) is 0/0 there. The same holds for any fractional power of an expression with an
    even power of a coordinate-dependent factor (√(θ²l²), (θ²)^0.5, √(θ² − 2θ + 1) = |θ − 1|);
    √(l²) of a constant and √(1 + θ²) are smooth and pass.
    """
    from mechanics.expr import ExprError

    for node in sp.preorder_traversal(value):
        if not (isinstance(node, sp.Pow) and _fractional(node.exp)):
            continue
        square = _square_factor(node.base)
        if square is not None:
            f = to_plain(square)
            raise ExprError(
                f"sqrt() of a square, here of {f}, is abs({f}): it has no derivative where "
                f"{f} = 0, and this expression is differentiated in time (a position or an "
                "angle): write it for the side the motion stays on",
                field=where,
            )


def _square_factor(base: sp.Expr) -> sp.Expr | None:
    """A coordinate-dependent f with f^(2k) a factor of ``base`` (after factoring), else None."""
    if not base.has(AppliedUndef):
        return None
    forms = [base, sp.factor(base)]
    if base.has(sp.sin, sp.cos) and sp.count_ops(base) <= 40:  # 1 − cos²θ = sin²θ
        forms.append(sp.factor(sp.trigsimp(base)))
    for form in forms:
        for factor in sp.Mul.make_args(form):
            if (
                isinstance(factor, sp.Pow)
                and factor.exp.is_integer
                and factor.exp.is_even
                and factor.base.has(AppliedUndef)
            ):
                return factor.base
    return None


def _unit(v: list[float] | None) -> tuple[float, float, float] | None:
    if v is None:
        return None
    v = [*v, 0.0][:3]
    big = max(abs(c) for c in v)  # scaled first: 1e-200 or 1e200 squared leaves double range
    v = [c / big for c in v]
    norm = sum(c * c for c in v) ** 0.5
    return (v[0] / norm, v[1] / norm, v[2] / norm)


class _Unresolved(Exception):
    pass


def _has_length(d: Vector, field: str) -> None:
    """Refuse a spring or damper whose ends are always at the same place: it has no direction."""
    if _tidy_square(d.dot(d)) == 0:
        from mechanics.spec import SpecError

        raise SpecError(
            [{"field": field, "message": "both ends are always at the same place: no length"}]
        )


def _tidy_square(d2: sp.Expr) -> sp.Expr:
    return sp.factor(sp.trigsimp(sp.expand(d2)))


def _length_of(
    d2: sp.Expr,
    forced: int | None = None,
    spec: SceneSpec | None = None,
    names: dict[str, sp.Expr] | None = None,
) -> tuple[sp.Expr, sp.Expr | None, int]:
    """ℓ = |d| as a textbook prints it: (ℓ, branch, sign).

    When d·d is a perfect square p² (every spring along a line), ℓ = |p|. A textbook writes ℓ = p
    or ℓ = −p, whichever is positive, with no |·| whose derivative would print sign(·). Where
    assumptions fix the sign (p = r > 0) that is exact; otherwise the sign is the side of the
    reference state (``forced``, else the spec's initial state, else +) and the branch p·sign is
    returned: the formula holds while it is > 0, and runs check it (start on the other side: the
    other sign; reach 0: stop).
    """
    d2 = _tidy_square(d2)
    if isinstance(d2, sp.Pow) and d2.exp == 2:
        base = d2.base
    elif d2.is_Mul and all(isinstance(f, sp.Pow) and f.exp == 2 for f in d2.args):
        base = sp.Mul(*(f.base for f in d2.args))
    else:
        return sp.sqrt(d2), None, 0
    if base.is_positive:
        return base, None, 1
    if base.is_negative:
        return -base, None, -1
    if spec is None or names is None:
        return sp.sqrt(d2), None, 0
    sign = forced if forced in (1, -1) else _reference_sign(base, spec, names)
    return sign * base, sign * base, sign


def _reference_sign(base: sp.Expr, spec: SceneSpec, names: dict[str, sp.Expr]) -> int:
    """The sign of p in the spec's own state (parameters, initial values, t = 0); + at p = 0."""
    number = reference_value(base, spec, names)
    return -1 if number is not None and number < 0 else 1


def reference_value(expr: sp.Expr, spec: SceneSpec, names: dict[str, sp.Expr]) -> float | None:
    """expr in the spec's own state (its parameters, its initial values or 0, t = 0)."""
    values: dict[sp.Expr, sp.Expr] = {names[k]: sp.Float(v) for k, v in spec.parameters.items()}
    for name in reversed(spec.coordinates):  # velocities before the coordinates inside them
        values[names[f"{name}_dot"]] = sp.Float(spec.initial.get(f"{name}_dot", 0.0))
    for name in spec.coordinates:
        values[names[name]] = sp.Float(spec.initial.get(name, 0.0))
    values[T] = sp.Integer(0)
    try:
        return float(expr.xreplace(values))
    except (TypeError, ValueError):
        return None
