"""Scene spec -> sympy.physics.vector frames, points, bodies and the forces on them.

The model is the one place where text becomes algebra: every expression of the spec goes through
the whitelist parser with the field path it came from, so a bad name is reported where it sits.
Nothing here differentiates energies; the steps do that from the model.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import sympy as sp
from sympy.physics.mechanics import Particle, RigidBody, inertia
from sympy.physics.vector import Point, ReferenceFrame, Vector, dynamicsymbols

from mechanics.expr import parse
from mechanics.spec import FramePosition, SceneSpec, parse_spec

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

    Parameters whose default is positive are declared nonnegative so that sqrt(l**2) prints as l;
    the simulation refuses negative values for them (a negative mass or length is an input error).
    """
    positive = set(spec.positive_coordinates)
    q = [
        dynamicsymbols(name, positive=True) if name in positive else dynamicsymbols(name)
        for name in spec.coordinates
    ]
    params = {
        name: sp.Symbol(name, nonnegative=True) if value > 0 else sp.Symbol(name, real=True)
        for name, value in spec.parameters.items()
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


def build_model(spec: SceneSpec | dict) -> Model:
    """Turn a validated spec into frames, points and bodies; raises ExprError with field paths."""
    if not isinstance(spec, SceneSpec):
        spec = parse_spec(spec)
    q, params, names = symbols_for(spec)
    # Accelerations never appear in a scene's geometry or forces.
    names = {k: v for k, v in names.items() if not k.endswith("_ddot")}
    N = ReferenceFrame("N", latexs=list(N_LATEX))
    O = Point("O")  # noqa: E741 — the notes' name for the origin
    O.set_vel(N, 0)

    def expr(value: Any, where: str, allow_velocity: bool = False) -> sp.Expr:
        table = names if allow_velocity else {k: v for k, v in names.items() if "_dot" not in k}
        return parse(value, table, field=where)

    frames: dict[str, FrameInfo] = {}
    for i, f in enumerate(spec.frames):
        parent = N if f.parent == "N" else frames[f.parent].frame
        angle = expr(f.angle, f"frames[{i}].angle")
        latex, plain = _frame_latex(f.name, f.unit_vectors)
        frame = ReferenceFrame(f.name, latexs=latex)
        frame.orient_axis(parent, getattr(parent, f.axis), angle)
        frames[f.name] = FrameInfo(f.name, frame, f.parent, f.axis, angle, plain)

    def frame_of(name: str) -> ReferenceFrame:
        return N if name == "N" else frames[name].frame

    positions: dict[str, Vector] = {"O": Vector(0)}
    natural: dict[str, str] = {"O": "N"}

    def vector(pos: Any, where: str, allow_velocity: bool = False) -> tuple[Vector, str, str]:
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
            v += expr(c, f"{path}[{j}]", allow_velocity) * getattr(fr, "xyz"[j])
        return v, frame_name, start

    def place(pos: Any, where: str) -> tuple[Vector, str]:
        v, frame_name, start = vector(pos, where)
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

    bodies: list[BodyInfo] = []
    for i, b in enumerate(spec.bodies):
        mass = expr(b.mass, f"bodies[{i}].mass")
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
            info.sympy_body = RigidBody(b.name, points[b.name], fr, mass, (dyadic, points[b.name]))
        else:
            info.sympy_body = Particle(b.name, points[b.name], mass)
        bodies.append(info)

    gravity = None
    if spec.gravity is not None:
        g = expr(spec.gravity.acceleration, "gravity.acceleration")
        d = [sp.nsimplify(c) for c in spec.gravity.direction] + [0] * (
            3 - len(spec.gravity.direction)
        )
        norm = sp.sqrt(sum(c**2 for c in d))
        gravity = (
            g,
            sum((c / norm * u for c, u in zip(d, (N.x, N.y, N.z), strict=True)), Vector(0)),
        )

    springs = []
    for i, s in enumerate(spec.springs):
        k = expr(s.k, f"springs[{i}].k")
        l0 = expr(s.rest_length, f"springs[{i}].rest_length")
        d = positions[s.b] - positions[s.a]
        length = _spring_length(d.dot(d), spec, names)
        d2 = length**2
        energy = k * d2 / 2 if l0 == 0 else k * (length - l0) ** 2 / 2
        springs.append(SpringInfo(s.name or f"spring{i + 1}", s.a, s.b, k, l0, length, energy))

    loads: list[Load] = []
    for i, dmp in enumerate(spec.dampers):
        c = expr(dmp.c, f"dampers[{i}].c")
        rel = positions[dmp.b].dt(N) - positions[dmp.a].dt(N)
        name = dmp.name or f"damper{i + 1}"
        loads.append(Load(name, "damper", dmp.b, -c * rel))
        if dmp.a != "O":
            loads.append(Load(name, "damper", dmp.a, c * rel))
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
    return Model(
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
    )


class _Unresolved(Exception):
    pass


def _spring_length(d2: sp.Expr, spec: SceneSpec, names: dict[str, sp.Expr]) -> sp.Expr:
    """ℓ = |d| as a textbook prints it.

    When |d|² is a perfect square p² (every spring along a line), ℓ = ±p with the sign it has in
    the scene's initial state: a spring cannot pass through zero length, so that sign holds for
    the whole motion, and V = ½k(ℓ − ℓ₀)² keeps no |·| whose derivative would print sign(·).
    """
    d2 = sp.factor(sp.trigsimp(sp.expand(d2)))
    if isinstance(d2, sp.Pow) and d2.exp == 2:
        base = d2.base
    elif d2.is_Mul and all(isinstance(f, sp.Pow) and f.exp == 2 for f in d2.args):
        base = sp.Mul(*(f.base for f in d2.args))
    else:
        return sp.sqrt(d2)
    values = {names[k]: v for k, v in spec.parameters.items()}
    for name in spec.coordinates:
        values[names[name]] = spec.initial.get(name, 0.0)
    value = base.subs(values)
    if value.is_number and value.is_real and value != 0:
        return base if value > 0 else -base
    return sp.sqrt(d2)
