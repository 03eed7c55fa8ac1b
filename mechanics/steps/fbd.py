"""Step 1 (notes IV.A 1): the free-body diagram — every force on every body, frames, datum.

Besides the applied forces, each body's constraint forces are named the way a textbook names them
and placed where they act (`constraint_forces`), all of one family with the weight F_g: a rod's
tension F_T at a bob, a track's or a wire's normal force F_N, a pin reaction F_pin at the pin, the
normal force F_N and static friction F_f at a rolling contact, a normal force F_N at each end of
a rod that slides along a fixed line (a ladder's F_N,wall and F_N,floor), F_C for a resultant left
unsplit when the contacts cannot be told from the kinematics and the inertia.
Never a bare letter: T is the kinetic energy, N the inertial frame, R a disk's radius or a frame's
name in the scenes. Only the names, the points and the directions come from here (kinematics
alone); the sizes are Newton's (`mechanics.newton`, F_C = m a − ΣF along a run).
"""

from __future__ import annotations

import random
from typing import Any

import sympy as sp
from sympy.physics.vector import Vector

from mechanics.expr import to_latex, to_plain
from mechanics.model import Model
from mechanics.newton_potentials import coordinate_potentials, unknown_constraint_forces
from mechanics.steps import Line, Step, Work, sub, tidy, vec_line
from mechanics.steps.energy import letter

#: A kinematic quantity counts as zero when it is below this at every sampled state.
ZERO = 1e-9


def body_forces(model: Model) -> dict[str, list[tuple[str, str, Vector]]]:
    """(label, kind, vector) of every force acting on each body or point, in N."""
    acting: dict[str, list[tuple[str, str, Vector]]] = {name: [] for name in model.positions}
    if model.gravity is not None:
        g, down = model.gravity
        for b in model.bodies:
            # F_g as the notes write the weight (eq. 28): W is work in the notes and the work panel
            acting[b.name].append((rf"\vec{{F}}_{{g,{sub(b.name)}}}", "weight", b.mass * g * down))
    for s in model.springs:
        d = model.positions[s.b] - model.positions[s.a]
        stretch = 1 if s.rest_length == 0 else (s.length - s.rest_length) / s.length
        pull = -s.k * stretch * d
        acting[s.b].append((rf"\vec{{F}}_{{{sub(s.name)}}}", "spring", pull))
        acting[s.a].append((rf"\vec{{F}}_{{{sub(s.name)}}}", "spring", -pull))
    for load in model.loads:
        acting[load.on].append(
            (
                rf"\vec{{{'M' if load.kind == 'torque' else 'F'}}}_{{{sub(load.name)}}}",
                load.kind,
                load.vector,
            )
        )
    return acting


# ---------------------------------------------------------------------------- kinematic tests
class _Sampler:
    """A few random states (q, q̇, t, parameters) at which kinematic identities are tested."""

    def __init__(self, model: Model, n: int = 4) -> None:
        rng = random.Random(7)
        t = model.names["t"]
        self.model = model
        self.states = []
        for _ in range(n):
            s: dict[Any, Any] = {p: sp.Float(rng.uniform(0.4, 1.3)) for p in model.params.values()}
            s.update({q: sp.Float(rng.uniform(0.2, 1.1)) for q in [*model.qdd, *model.qd]})
            s.update({q: sp.Float(rng.uniform(0.2, 1.1)) for q in model.q})
            s[t] = sp.Float(rng.uniform(0.2, 1.1))
            self.states.append(s)

    def values(self, v: Vector) -> list[list[float]]:
        N = self.model.N
        comps = [v.dot(u) for u in (N.x, N.y, N.z)]
        return [[float(c.xreplace(s)) for c in comps] for s in self.states]

    def zero(self, v: Vector) -> bool:
        return all(abs(x) <= ZERO for row in self.values(v) for x in row)

    def rank(self, vectors: list[Vector]) -> int:
        import numpy as np

        if not vectors:
            return 0
        return max(
            int(np.linalg.matrix_rank(np.array(rows), tol=1e-7))
            for rows in zip(*(self.values(v) for v in vectors), strict=True)
        )


def _explicit_t(v: Vector, model: Model) -> Vector:
    """∂v/∂t at fixed q: nonzero only for a constraint that moves with time (a spinning hoop)."""
    plain = {q: sp.Dummy() for q in model.q}
    back = {d: q for q, d in plain.items()}
    t = model.names["t"]
    N = model.N
    return sum(
        (v.dot(u).xreplace(plain).diff(t).xreplace(back) * u for u in (N.x, N.y, N.z)), Vector(0)
    )


def _planar(model: Model, s: _Sampler) -> bool:
    """Everything happens in the x–y plane of N: bodies, forces and every turn about N.z."""
    z = model.N.z
    if any(not s.zero(p.dot(z) * z) for p in model.positions.values()):
        return False
    for info in model.frames.values():
        w = info.frame.ang_vel_in(model.N)
        if not s.zero(w - w.dot(z) * z):
            return False
    return True


def _anchor(model: Model, name: str) -> str:
    spec_body = next(x for x in model.spec.bodies if x.name == name)
    return getattr(spec_body.position, "from_", None) or "O"


def _hangers(model: Model, name: str) -> list[str]:
    """Bodies placed from this one (`from`)."""
    return [b.name for b in model.bodies if b.name != name and _anchor(model, b.name) == name]


def _chain(model: Model, name: str) -> set[str]:
    """The body, every body it is placed from, and every body placed from it (transitively)."""
    up, x = {name}, name
    while (x := _anchor(model, x)) in {b.name for b in model.bodies}:
        up.add(x)
    down, todo = set(), [name]
    while todo:
        for h in _hangers(model, todo.pop()):
            down.add(h)
            todo.append(h)
    return up | down


def _directions(model: Model, place: Vector) -> list[Vector]:
    return [place.diff(q, model.N) for q in model.q]


def _moved_by(model: Model, v: Vector, s: _Sampler) -> list:
    return [q for q in model.q if not s.zero(v.diff(q, model.N))]


# ---------------------------------------------------------------------------- classification
def rod_anchor(model: Model, name: str, sampler: _Sampler | None = None) -> str | None:
    """The place a particle hangs from by a rod (or string), when that rod is its only constraint.

    It keeps a fixed distance from its anchor, the constraint does not move with time, and
    relative to the anchor it may move in every direction but along the rod: then its own
    constraint force is the rod's pull along the rod, a tension F_T. A bead on a spinning hoop keeps
    its distance too, but the hoop also pushes it across: that is a normal force, not a tension.
    """
    s = sampler or _Sampler(model)
    body = next(b for b in model.bodies if b.name == name)
    if body.kind != "particle":
        return None
    anchor = _anchor(model, name)
    rel = model.positions[name] - model.positions[anchor]
    length2 = tidy(rel.dot(rel), model)
    if length2 == 0 or any(length2.has(q) for q in model.q) or length2.has(model.names["t"]):
        return None
    if not s.zero(_explicit_t(rel, model)):
        return None
    free = 2 if _planar(model, s) else 3
    return anchor if s.rank(_directions(model, rel)) == free - 1 else None


def _unit(v: Vector, model: Model) -> list[str]:
    n = sp.sqrt(tidy(v.dot(v), model))
    return [to_plain(tidy(v.dot(u) / n, model)) for u in (model.N.x, model.N.y, model.N.z)]


def _point(v: Vector, model: Model) -> list[str]:
    return [to_plain(tidy(v.dot(u), model)) for u in (model.N.x, model.N.y, model.N.z)]


def _force(
    name: str, on: str, what: str, at: str | list[str], label_of: str | None = None, **how: Any
) -> dict[str, Any]:
    letter, _, index = name.partition("_")
    label = rf"\vec{{{letter}}}_{{{sub(index) + ',' if index else ''}{sub(label_of or on)}}}"
    symbol = [letter, f"{index},{label_of or on}" if index else (label_of or on)]
    return {"name": name, "label": label, "symbol": symbol, "what": what, "on": on, "at": at, **how}


def _rigid_contact(model: Model, body: Any, s: _Sampler) -> tuple[list[dict], str] | None:
    """A planar rigid body moved by one coordinate: where its constraints act, when it can be told.

    The instantaneous centre P = G + ẑ × v_G / ω has zero velocity; if it is fixed in space it is
    a pin (reaction F_pin). Else the body rolls on the path P traces (normal force F_N across it,
    static friction F_f along it — no slip, so friction is static) only if P is a point of the
    body, on its rim (`_on_body`): every planar motion has a moving instantaneous centre, and a
    sliding ladder's lies off the rod, where nothing touches it. Then its constraints act where
    its points slide along fixed lines (`_sliding_ends`), or, not told, as a resultant (None).
    """
    moves = _moved_by(model, body.position, s)
    t = model.names["t"]
    if body.frame is None or len(moves) != 1 or not _planar(model, s):
        return None
    if not s.zero(_explicit_t(body.position, model)):
        return None
    q = moves[0]
    qd = model.qd[model.q.index(q)]
    w = body.frame.ang_vel_in(model.N).dot(model.N.z)
    one = {qd: 1}
    omega = tidy(w.subs(one), model)
    if omega == 0 or omega.has(t):
        return None
    v = body.position.dt(model.N).subs(one)
    centre = body.position + model.N.z.cross(v) / omega
    centre = sum(
        (tidy(centre.dot(u), model) * u for u in (model.N.x, model.N.y, model.N.z)), Vector(0)
    )
    at = _point(centre, model)
    name = body.name
    if s.zero(centre.diff(q, model.N)):
        pin = next((p for p, r in model.positions.items() if s.zero(r - centre)), None)
        where = f"the pin at {pin}" if pin else "the pin"
        force = _force("F_pin", name, f"pin reaction on {name}, at {where}", at, part="rest")
        return [force], (
            f"the pin reaction ${force['label']}$ acts at {where}, a point of {name} that never "
            f"moves: its virtual displacement is zero, so ${force['label']}$ does no virtual "
            "work (though it is not perpendicular to "
            rf"$\partial \vec r_G/\partial {to_latex(q)}$ in general)"
        )
    if not _on_body(model, body, centre, s):  # the centre of a sliding ladder, off the rod
        return _sliding_ends(model, body, q, s)
    tangent = centre.diff(q, model.N)
    normal = model.N.z.cross(tangent)
    if tidy((body.position - centre).dot(normal), model).subs(s.states[0]) < 0:
        normal = -normal
    forces = [
        _force(
            "F_N",
            name,
            f"normal force on {name} at the contact",
            at,
            part="rest",
            along=_unit(normal, model),
        ),
        _force(
            "F_f",
            name,
            f"static friction on {name} at the contact",
            at,
            part="rest",
            along=_unit(tangent, model),
        ),
    ]
    normal_label, friction_label = forces[0]["label"], forces[1]["label"]
    return forces, (
        f"${normal_label}$ and ${friction_label}$ act at the contact point, the point of {name} "
        "at rest while it rolls without slipping: its virtual displacement is zero, so they do "
        rf"no virtual work (though ${friction_label}$ is along "
        rf"$\partial \vec r_G/\partial {to_latex(q)}$)"
    )


# ---------------------------------------------------------------------------- a body's extent
#: Relative size below which a spread of mass counts as zero (a rod's thickness) or equal (round).
SPREAD = 1e-9


def _spreads(model: Model, body: Any, s: _Sampler) -> list[Any] | None:
    """∫ r rᵀ dm about G in the plane of the motion (N.x, N.y), at each sampled state.

    The spec gives no shape, only the central inertia; its spread in the plane is what it says
    about where the mass is: ∫x² = (I_yy + I_zz − I_xx)/2, ∫xy = −I_xy. A rod has all its mass on
    one line (one spread zero), a disk or a ring is round (the two equal).
    """
    import numpy as np

    if body.inertia is None:
        return None
    N = model.N
    rows = [s.values(body.inertia.dot(u)) for u in (N.x, N.y, N.z)]  # [i][state]: I·u_i in N
    out = []
    for ix, iy, iz in zip(*rows, strict=True):
        sxx, syy = (iy[1] + iz[2] - ix[0]) / 2, (ix[0] + iz[2] - iy[1]) / 2
        out.append(np.array([[sxx, -ix[1]], [-ix[1], syy]]))
    return out


def _components(v: Vector, model: Model, s: _Sampler) -> list[Any]:
    import numpy as np

    return [np.array(row[:2]) for row in s.values(v)]


def _rod_axis(model: Model, body: Any, s: _Sampler) -> Vector | None:
    """The unit vector along a rod (all its mass on one line through G in the plane), one of its
    frame's axes; None for a body with breadth, or a rod along no axis of its frame."""
    import numpy as np

    spreads = _spreads(model, body, s)
    if spreads is None:
        return None
    for S in spreads:
        low, high = np.linalg.eigvalsh(S)
        if high <= 0 or low > SPREAD * high:
            return None
    for axis in (body.frame.x, body.frame.y, body.frame.z):
        if not s.zero(axis.dot(model.N.z) * model.N.z):
            continue
        across = _components(model.N.z.cross(axis), model, s)
        if all(n @ S @ n <= SPREAD * np.trace(S) for n, S in zip(across, spreads, strict=True)):
            return axis
    return None


def _on_body(model: Model, body: Any, centre: Vector, s: _Sampler) -> bool:
    """Whether the moving point at rest is a point of the body where a surface can touch it.

    A rod: P on its line (a plank rocking on a log rolls along itself). A round body (its mass
    spread alike every way in the plane): P a fixed distance d from G, and I_zz between a solid
    sphere's 2/5 m d² and a ring's m d², the round bodies that roll on a rim of radius d — a disk,
    a cylinder, a ball, a hoop. Outside that band the body is not known to be a wheel of radius d:
    a yo-yo's hub, or a square plate whose diagonal slides between a wall and a floor (P is a
    corner's distance from G, I_zz = m d²/3, and no point of the plate is at P). Anything else is
    not known to reach P either, so no rolling contact is claimed for it.
    """
    import numpy as np

    rel = centre - body.position
    axis = _rod_axis(model, body, s)
    if axis is not None:
        return s.zero(rel.cross(axis))
    spreads = _spreads(model, body, s)
    if spreads is None:
        return False
    for S in spreads:
        size = np.trace(S)
        if size <= 0 or abs(S[0, 0] - S[1, 1]) > SPREAD * size or abs(S[0, 1]) > SPREAD * size:
            return False
    d2 = tidy(rel.dot(rel), model)
    if any(d2.has(q) for q in model.q) or d2.has(model.names["t"]):
        return False
    for S, st in zip(spreads, s.states, strict=True):
        ring = float(body.mass.xreplace(st)) * float(d2.xreplace(st))  # m d²
        if not (0.4 - SPREAD) * ring <= np.trace(S) <= (1 + SPREAD) * ring:
            return False
    return True


def _line_direction(v: Vector, model: Model, s: _Sampler) -> Vector | None:
    """The unit vector of v when its direction never changes with the coordinates (the velocity
    of a point that slides along a fixed straight line), else None."""
    import numpy as np

    comps = [v.dot(u) for u in (model.N.x, model.N.y)]
    k = int(np.argmax(np.abs(_components(v, model, s)[0])))
    if not comps[k] or any(abs(x[k]) <= ZERO for x in _components(v, model, s)):
        return None
    ratios = [tidy(c / comps[k], model) for c in comps]
    if any(r.has(q) for r in ratios for q in model.q) or any(
        r.has(model.names["t"]) for r in ratios
    ):
        return None
    size = sp.sqrt(tidy(sum(r**2 for r in ratios), model))
    return sum(
        (tidy(r / size, model) * u for r, u in zip(ratios, (model.N.x, model.N.y), strict=True)),
        Vector(0),
    )


def _sliding_ends(model: Model, body: Any, q: Any, s: _Sampler) -> tuple[list[dict], str] | None:
    """A rod whose point at rest is off it (a ladder between a wall and a floor): the two points of
    it that slide along fixed straight lines are where its constraints act, each a normal force.

    Found from the kinematics: a point G + σ ê of the rod moves on a straight line where its path
    does not curve, (∂r/∂q × ∂²r/∂q²)·ẑ = 0 at every q — a quadratic in σ. Claimed only when that
    gives two points on the rod (|σ| within a uniform rod's half-length √(3 ∫σ² dm / m)) sliding
    along perpendicular lines, the two normal forces then being the two components of Newton's
    resultant; else None, and only the resultant is drawn. One body only, so the lines' names (the
    wall, the floor) label its forces without a clash.
    """
    axis = _rod_axis(model, body, s)
    if axis is None or len(model.bodies) != 1:
        return None
    N, G = model.N, body.position
    sigma = sp.Dummy("sigma")
    r1 = (G + sigma * axis).diff(q, N)
    bend = sp.expand(r1.cross(r1.diff(q, N)).dot(N.z))
    coeffs = [bend.coeff(sigma, k) for k in (2, 1, 0)]
    values = [[abs(float(c.xreplace(st))) for c in coeffs] for st in s.states]
    lead = next((k for k in (0, 1) if all(v[k] > ZERO for v in values)), None)
    if lead is None:
        return None
    monic = [tidy(c / coeffs[lead], model) for c in coeffs[lead:]]
    if any(c.has(x) for c in monic for x in (*model.q, model.names["t"])):
        return None
    roots = [
        tidy(r, model)
        for r in sp.solve(
            sum(c * sigma ** (len(monic) - 1 - k) for k, c in enumerate(monic)), sigma
        )
    ]
    if len(roots) != 2:
        return None
    # a uniform rod's half-length squared, 3 ∫σ² dm / m, at each sampled state: how far it reaches
    reach = [
        3 * float(a @ S @ a) / float(body.mass.xreplace(st))
        for a, S, st in zip(
            _components(axis, model, s), _spreads(model, body, s), s.states, strict=True
        )
    ]
    ends = []
    for root in roots:
        at = [complex(root.xreplace(st)) for st in s.states]
        if any(abs(z.imag) > ZERO for z in at):
            return None
        if any(z.real**2 > (1 + SPREAD) * a2 for z, a2 in zip(at, reach, strict=True)):
            return None
        point = G + root * axis
        along = _line_direction(point.diff(q, N), model, s)
        if along is None:
            return None
        normal = N.z.cross(along)
        if float((G - point).dot(normal).xreplace(s.states[0])) < 0:
            normal = -normal
        at_end = all(abs(z.real**2 - a2) <= SPREAD * a2 for z, a2 in zip(at, reach, strict=True))
        ends.append((point, along, normal, at_end))
    (p1, u1, n1, end1), (p2, u2, n2, end2) = ends
    if not s.zero(n1.dot(n2) * N.z):
        return None
    names = [_surface(model, u, n, s) for u, n in ((u1, n1), (u2, n2))]
    if names[0] == names[1] or "" in names:
        names = ["1", "2"]
    name = body.name
    forces = []
    for (point, _, normal, at_end), where in zip(ends, names, strict=True):
        place = "its end" if at_end else "its point"
        surface = f"the {where}" if where in ("wall", "floor", "ceiling") else "a fixed line"
        forces.append(
            _force(
                "F_N",
                name,
                f"normal force of {surface} on {name}, at {place} that slides along it",
                _point(point, model),
                label_of=where,
                part="rest",
                along=_unit(normal, model),
            )
        )
    points = "ends" if end1 and end2 else "points"
    lines = (
        f"along the {names[0]} and the {names[1]}"
        if all(w in ("wall", "floor", "ceiling") for w in names)
        else "along two perpendicular fixed straight lines"
    )
    first, second = forces[0]["label"], forces[1]["label"]
    return forces, (
        f"its {points} slide {lines}, and each is pushed across its line: the normal forces "
        f"${first}$ and ${second}$ act there, each perpendicular to the only virtual "
        "displacement of the point it acts at (along its line), so they do no virtual work "
        "(smooth contacts, as the equations of motion assume)"
    )


def _surface(model: Model, along: Vector, normal: Vector, s: _Sampler) -> str:
    """A fixed line by what it is under gravity: a wall (vertical), a floor or a ceiling."""
    if model.gravity is None:
        return ""
    down = model.gravity[1]
    if s.zero(along.cross(down)):
        return "wall"
    if s.zero(along.dot(down) * model.N.z):
        return "floor" if float(normal.dot(down).xreplace(s.states[0])) < 0 else "ceiling"
    return ""


def _coupled_to(model: Model, name: str, s: _Sampler) -> list[str]:
    """Other bodies, not hanging from it nor holding it, that its own coordinates move too."""
    body = next(b for b in model.bodies if b.name == name)
    rel = model.positions[name] - model.positions[_anchor(model, name)]
    mine = set(_moved_by(model, rel, s))
    if body.frame is not None:
        w = body.frame.ang_vel_in(model.N)
        mine |= {
            q for q, qd in zip(model.q, model.qd, strict=True) if not s.zero(w.diff(qd, model.N))
        }
    chain = _chain(model, name)
    return [
        b.name
        for b in model.bodies
        if b.name not in chain and mine & set(_moved_by(model, model.positions[b.name], s))
    ]


def _straight_rope(model: Model, name: str, s: _Sampler) -> bool:
    """Moves along one fixed vertical line, and every applied force on it is along that line:
    what holds it back along the line is a rope's pull."""
    J = [d for d in _directions(model, model.positions[name]) if not s.zero(d)]
    if len(J) != 1 or model.gravity is None or not s.zero(_explicit_t(J[0], model)):
        return False
    line = J[0]
    if any(not s.zero(line.diff(q, model.N)) for q in model.q):
        return False
    applied = sum((v for _, k, v in body_forces(model)[name] if k != "torque"), Vector(0))
    return s.zero(model.gravity[1].cross(line)) and s.zero(applied.cross(line))


def constraint_forces(model: Model) -> tuple[dict[str, list[dict[str, Any]]], list[str]]:
    """Each body's constraint forces, named and placed, and one true sentence per body on their
    virtual work (per body only where it is provable; for the system, eq. 18–20)."""
    s = _Sampler(model)
    names = {b.name for b in model.bodies}
    rods = {b.name: rod_anchor(model, b.name, s) for b in model.bodies}
    forces: dict[str, list[dict[str, Any]]] = {b.name: [] for b in model.bodies}
    for b, anchor in rods.items():
        if anchor in names:  # the rod from `anchor` to b pulls on both its ends
            forces[anchor].append(
                _force(
                    "F_T",
                    anchor,
                    f"pull of the rod from {anchor} to {b}",
                    anchor,
                    part="pull",
                    rod=b,
                    label_of=b,
                )
            )
    notes = []
    for body in model.bodies:
        name = body.name
        moves = _moved_by(model, body.position, s)
        coords = ", ".join(to_latex(q) for q in moves)
        if not moves and body.frame is None:
            notes.append(f"{name}: held fixed by its constraints")
            continue
        coupled = _coupled_to(model, name, s)
        hangers = _hangers(model, name)
        anchor = _anchor(model, name)
        fixed_anchor = (
            anchor not in names
            and s.zero(_explicit_t(model.positions[anchor], model))
            and not _moved_by(model, model.positions[anchor], s)
        )
        alone = not coupled and not hangers and fixed_anchor
        driven = not s.zero(_explicit_t(body.position, model))
        free = 2 if _planar(model, s) else 3
        own = None  # (force entries, why they do no virtual work) when provable
        if rods[name] is not None:
            rod = rods[name]
            tension = _force(
                "F_T",
                name,
                f"tension of the rod from {rod} to {name}",
                name,
                part="rest",
                toward=rod,
            )
            own = ([tension], f"the rod's pull ${tension['label']}$ is along the rod")
        elif body.kind == "particle":
            k = s.rank(_directions(model, body.position))
            if not coupled and k < free:
                where = "track" if k == 1 else "surface"
                normal = _force(
                    "F_N", name, f"normal force of the {where} on {name}", name, part="rest"
                )
                own = ([normal], f"the {where}'s normal force ${normal['label']}$ is across it")
            elif coupled and _straight_rope(model, name, s):
                forces[name].append(
                    _force("F_T", name, f"pull of the rope on {name}", name, part="rest")
                )
            elif coupled or k < free:
                forces[name].append(
                    _force("F_C", name, f"constraint force on {name}", name, part="rest")
                )
        elif not coupled and (contact := _rigid_contact(model, body, s)) is not None:
            forces[name] += contact[0]
            if alone:
                notes.append(f"{name}: it moves only with ${coords}$; {contact[1]}")
                continue
        else:
            forces[name].append(
                _force(
                    "F_C",
                    name,
                    f"resultant of the constraint forces on "
                    f"{name} (drawn at its centre; a constraint moment too)",
                    name,
                    part="rest",
                )
            )
        if own is not None:
            forces[name] += own[0]
        if alone and own is not None:
            note = (
                f"{name}: its only constraint is its own; it moves only with ${coords}$, and "
                rf"{own[1]}, perpendicular to every $\partial \vec r/\partial q_j$, so it does no "
                "virtual work"
            )
            if driven:
                note += (
                    " (the constraint moves with time, so it does do real work: a virtual "
                    "displacement is taken at fixed t)"
                )
        elif alone and body.frame is not None and [f["name"] for f in forces[name]] == ["F_C"]:
            note = (
                f"{name}: its only constraints are its own; it moves only with ${coords}$. Where "
                "they act (contacts, a pin) the kinematics and the inertia do not tell, so only "
                f"their resultant ${forces[name][0]['label']}$ is drawn, at its centre, with a "
                "constraint moment; together they do no virtual work (ideal constraints, "
                "eq. 18–20)"
            )
        elif alone and body.kind == "particle" and not forces[name]:
            note = f"{name}: no constraint acts on it (it moves freely with ${coords}$)"
            if free == 2 and body.position.dot(model.N.z) == 0:
                across = (  # V(q) says nothing of a push across the plane (newton_potentials)
                    "whether the scene's potential pushes across it V(q) cannot say"
                    if coordinate_potentials(model)
                    else "no force pushes across it, so that constraint's force is zero"
                )
                note = (
                    f"{name}: it moves freely in the plane of the motion with ${coords}$; the "
                    f"plane itself (z = 0) is its one constraint, and {across}"
                )
        else:
            why = []
            if coupled:
                why.append(f"its coordinates also move {', '.join(coupled)}")
            if hangers:
                why.append(f"{', '.join(hangers)} hang{'s' if len(hangers) == 1 else ''} from it")
            if not fixed_anchor:
                why.append(f"it hangs from {anchor}, which moves")
            note = (
                f"{name}: moves with ${coords}$; {' and '.join(why) or 'it shares constraints'}"
                f", so the constraint forces on {name} need not be perpendicular to every "
                rf"$\partial \vec r/\partial q_j$: on {name} alone they may do virtual work, "
                "summed over all bodies they do none (ideal constraints, eq. 18–20)"
            )
        notes.append(note)
    return forces, notes


def resultant_name(placed: list[dict[str, Any]]) -> str:
    """The name of a body's whole constraint force (Newton's m a − ΣF) as the FBD calls it.

    One force of its own and no rod pulling from it: that force's name (the Atwood rope's F_T, a
    bead's F_N), so the Newton panel and the diagram say one name for one force; otherwise the
    resultant F_C of the several the diagram draws (a rolling disk's F_N + F_f)."""
    if len(placed) == 1 and placed[0].get("part") == "rest":
        return placed[0]["name"]
    return "F_C"


def free_body_diagram(model: Model, work: Work) -> Step:
    """Forces as vectors, constraint forces named and placed, frames and datum.

    ``data``:
      ``bodies``: per body ``{"body", "kind", "free_directions", "forces", "constraint_forces"}``;
        ``forces`` are the applied ones (label, kind, plain, components in N);
        ``constraint_forces`` each ``{"name", "label", "what", "on", "at", "part", ...}``:
        ``name`` of the F family (F_T tension of a rod or rope, F_N normal force, F_f static
        friction, F_pin pin reaction, F_C an unnamed resultant; ``symbol``: its letter and subscript
        in plain text, ``what``: in words), ``at`` where it acts: a place of the
        run's ``positions`` (a body, a point) or its N components as plain expressions in the
        coordinates and parameters (a pin, a rolling contact). Its size comes from Newton's
        constraint force F_C = m a − ΣF of the run (`constraint_forces` of /simulate):
        ``part = "pull"``: the rod of body ``rod`` pulls this end toward ``rod`` with that rod's
        tension; ``part = "rest"``: F_C less the pulls listed on the same body, projected on
        ``along`` (unit vector, N components) or on the direction ``toward`` a place when given.
      ``constraints``: one sentence per body on the virtual work of its constraint forces.
      ``datum``: where V = 0.
    """
    acting = body_forces(model)
    placed, notes = constraint_forces(model)
    unknown = unknown_constraint_forces(model)
    if unknown is not None:  # drawn where they act, but no size: say so, as /newton does
        notes = [*notes, unknown]
    lines: list[Line] = []
    drawn = []
    for b in model.bodies:
        forces = []
        for label, kind, vec in acting[b.name]:
            lines.append(vec_line(label, vec, "N", model, f"{kind} on {b.name}"))
            forces.append(
                {
                    "label": label,
                    "kind": kind,
                    "plain": lines[-1].plain,
                    "components": [
                        to_plain(tidy(vec.dot(u), model)) for u in (model.N.x, model.N.y, model.N.z)
                    ],
                }
            )
        drawn.append(
            {
                "body": b.name,
                "kind": b.kind,
                "forces": forces,
                "free_directions": 3 if b.kind == "particle" else 6,
                "constraint_forces": placed[b.name],
            }
        )
    for name, info in model.frames.items():
        w = info.frame.ang_vel_in(model.N)
        lines.append(
            vec_line(
                rf"\vec{{\omega}}_{{{name}/N}}", w, name, model, f"angular velocity of frame {name}"
            )
        )
    heights = "every body at the height of O" if model.gravity is not None else ""
    rest = "every spring at its rest length" if model.springs else ""
    V = letter(model, "V")
    Q_ = letter(model, "Q")
    datum = (
        f"${V} = 0$ with {' and '.join(filter(None, [heights, rest]))}"
        if heights or rest
        else f"${V}$ as the scene's potentials give it"
    )
    text = (
        "Draw every force on every body, the constraint forces where they act. Weights, springs "
        f"and potentials are conservative and enter through ${V}$; dampers and applied forces do "
        f"non-conservative work and enter through ${Q_}_j^{{NC}}$. For ideal constraints the "
        "constraint forces on all bodies together do no virtual work (notes eq. 18–20); on one "
        f"body alone only when its constraints are its own. Datum: {datum}."
    )
    if model.frames:  # ω_{D/N} below is the first place N appears
        first = next(iter(model.frames))
        text += (
            r" N is the fixed (inertial) frame, the notes' F, with unit vectors "
            rf"$\hat\imath, \hat\jmath, \hat k$; $\vec\omega_{{{first}/N}}$ is the angular "
            f"velocity of frame {first} relative to N."
        )
    if model.gravity is None:
        text += (
            r" There is no uniform gravity in this scene (no weight $m\vec g$ on any body), so "
            "none is drawn."
        )
    return Step(
        "fbd",
        "Free-body diagram",
        text,
        lines,
        {"bodies": drawn, "constraints": notes, "datum": datum},
    )
