"""Newton's method beside Lagrange's (notes I.A): Σ F = m a per particle, constraint forces kept.

Each particle's balance m a = F + F_C is written along the unit vectors of the frame its position
is natural in (polar for a pendulum). The constraint force F_C is the unknown Lagrange never needs:
projected on the directions the particle may move (∂r/∂q_j) the balances give back the equations
of motion (D'Alembert, eq. 19–20); projected on the other directions they give F_C itself, here
solved with q̈ from the equations of motion: the tension F_T(θ, θ̇) of a pendulum, the normal
force F_N of a hoop, the tension F_T of the Atwood machine's string. Each is called what the
free-body diagram calls it (`fbd.resultant_name`): one force, one name on both panels, and never
a scene's parameter (R is a radius) nor the kinetic energy T.

A scene's `potentials` are V(q, t), not forces on a body: V fixes only their virtual work, so
where one depends on the coordinates no constraint force is computed and the reason is given
instead (`newton_potentials`); the balances projected on δq_j carry −∂V/∂q_j and still hold.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import sympy as sp
from sympy.physics.vector import Vector

from mechanics.derive import Derivation
from mechanics.expr import to_latex, to_plain
from mechanics.newton_potentials import (
    potential_forces,
    potential_virtual_work,
    unknown_constraint_forces,
)
from mechanics.steps import Line, Step, sub, tidy, vec_in, vec_line
from mechanics.steps.fbd import body_forces, constraint_forces, resultant_name, rod_anchor


@dataclass
class ConstraintForce:
    body: str
    frame: str
    vector: Vector  # R = m a − ΣF, with q̈ from the equations of motion
    components: list[sp.Expr]  # along the natural frame's unit vectors
    support: tuple[str, sp.Expr] | None = None  # (point, tension toward it) for a rod or string
    name: str = "F_C"  # as the free-body diagram names it: F_T, F_N, F_pin, or F_C (a resultant)
    parts: tuple[str, ...] = ()  # the diagram's labels of the forces F_C sums, when several

    @property
    def label(self) -> str:
        letter, _, index = self.name.partition("_")
        return rf"\vec{{{letter}}}_{{{sub(index)},{sub(self.body)}}}"


def newton(d: Derivation) -> tuple[list[Step], list[ConstraintForce], list[sp.Expr]]:
    """Steps, the constraint force on every particle (none where a potential V(q) leaves them
    unknown), and the equations Newton's method gives."""
    m = d.model
    acting = body_forces(m)
    placed, _ = constraint_forces(m)
    solved = dict(zip(m.qdd, d.solved_accelerations, strict=True))
    balance_lines: list[Line] = []
    forces: list[ConstraintForce] = []
    residual = [sp.S.Zero] * len(m.q)  # Σ_i (m a_i − F_i)·∂r_i/∂q_j, torques included
    # a potential V(q) fixes only its force's virtual work, not the force (newton_potentials)
    unknown = unknown_constraint_forces(m)
    pushes = potential_forces(m) or {}  # −∇V on free particles: then in ΣF, not added apart
    for j, dV in enumerate(potential_virtual_work(m)):
        residual[j] += 0 if pushes else dV
    for b in m.bodies:
        a = m.velocity(b.name).dt(m.N)
        applied = sum((vec for _, kind, vec in acting[b.name] if kind != "torque"), Vector(0))
        applied += pushes.get(b.name, Vector(0))
        frame = b.natural_frame
        balance_lines.append(
            vec_line(rf"m\vec{{a}}_{{{sub(b.name)}}}", b.mass * a, frame, m, f"m a of {b.name}")
        )
        balance_lines.append(
            vec_line(
                rf"\sum\vec{{F}}_{{{sub(b.name)}}}",
                applied,
                frame,
                m,
                f"applied forces on {b.name}",
            )
        )
        R = b.mass * a - applied
        for j, q in enumerate(m.q):
            residual[j] += R.dot(b.position.diff(q, m.N))
        if unknown is None:
            R_solved = sum(
                (c.xreplace(solved) * u for c, u in _components(R, m.frame(frame))), Vector(0)
            )
            R_nice, comps = vec_in(R_solved, frame, m)
            support = _support_force(b, R_nice, m)
            name = resultant_name(placed[b.name])
            # a rod's pull is labelled by the rod (the same label on both its ends, opposite
            # forces), so a sum of labels is written only over the body's own forces
            own = [f["label"] for f in placed[b.name] if f.get("part") == "rest"]
            whole = name == "F_C" and len(own) == len(placed[b.name])
            parts = tuple(own) if whole else ()
            forces.append(ConstraintForce(b.name, frame, R_nice, comps, support, name, parts))
            if support is not None and frame == "N":
                balance_lines += _polar_lines(b, support[0], b.mass * a, applied, m)
        if b.frame is not None:  # Σ M_G = dH_G/dt (eq. 11); the constraint moment is the rest
            omega = b.frame.ang_vel_in(m.N)
            dH = b.inertia.dot(omega).dt(m.N)
            torques = [ld.vector for ld in m.loads if ld.kind == "torque" and ld.on == b.name]
            torque = sum(torques, Vector(0))
            balance_lines.append(
                vec_line(r"\frac{d\vec{H}_{G}}{dt}", dH, "N", m, f"dH/dt of {b.name}")
            )
            for j, qd in enumerate(m.qd):
                residual[j] += (dH - torque).dot(omega.diff(qd, m.N))
    steps = _steps(d, balance_lines, forces, unknown)
    return steps, forces, [tidy(r, m) for r in residual]


def _support_force(b: Any, R: Vector, m: Any) -> tuple[str, sp.Expr] | None:
    """Tension toward the point a particle hangs from, when a rod of fixed length is its only
    constraint (`rod_anchor`): a bead on a spinning hoop keeps its distance from the centre too,
    but the hoop's push is a normal force, not a tension; a rigid body's pin reaction is not one
    either (it has a part across the line to the pin)."""
    hangers = [
        x for x in [*m.spec.bodies, *m.spec.points] if getattr(x.position, "from_", None) == b.name
    ]
    if hangers:  # another body pulls on it too: R is not one rod's tension
        return None
    anchor = rod_anchor(m, b.name)
    if anchor is None:
        return None
    rel = b.position - m.positions[anchor]
    tension = tidy(-R.dot(rel) / sp.sqrt(tidy(rel.dot(rel), m)), m)
    return anchor, tension


def _polar_lines(b: Any, anchor: str, ma: Vector, applied: Vector, m: Any) -> list[Line]:
    """A pendulum declared in x, y, balanced as the notes do: along ê_r (to the bob) and ê_θ.

    Along the rod the tension F_T enters (m a·ê_r = ΣF·ê_r − F_T); across it nothing does.
    """
    rel = b.position - m.positions[anchor]
    if tidy(rel.dot(m.N.z), m) != 0:
        return []  # not planar: the spherical basis of the scene's own frames is used instead
    e_r = rel / sp.sqrt(tidy(rel.dot(rel), m))
    e_t = m.N.z.cross(e_r)
    name = sub(b.name)
    lines = []
    tension = (rf" - F_{{T,{name}}}", f" - F_T_{b.name}")
    for label, e, (extra, extra_plain) in (("r", e_r, tension), (r"\theta", e_t, ("", ""))):
        lhs, rhs = tidy(ma.dot(e), m), tidy(applied.dot(e), m)
        lines.append(
            Line(
                f"{'radial' if label == 'r' else 'tangential'} balance of {b.name}",
                rf"m a_{{{label}}} = {to_latex(lhs)} = {to_latex(rhs)}{extra}\quad({name})",
                f"m a_{label.strip(chr(92))} = {to_plain(lhs)} = {to_plain(rhs)}{extra_plain}",
            )
        )
    return lines


def _components(v: Vector, frame) -> list[tuple[sp.Expr, Vector]]:
    return [(v.dot(u), u) for u in (frame.x, frame.y, frame.z)]


def _steps(
    d: Derivation, balances: list[Line], forces: list[ConstraintForce], unknown: str | None
) -> list[Step]:
    """The two steps; ``unknown`` (why the constraint forces are not computed) replaces the
    promise of the second, so that no step promises a force the response does not carry."""
    m = d.model
    text = (
        "For each particle write Σ F = m a (eq. 10) along the unit vectors of its natural "
        r"frame, with the constraint force as an unknown: $m\vec a = \sum \vec F + \vec F_C$, "
        r"$\vec F_C$ named as in the free-body diagram (the rope's or rod's $\vec F_T$, a "
        r"normal force $\vec F_N$) when it is one force there."
    )
    if m.potentials and unknown is None and potential_forces(m):
        text += (
            " No constraint acts on any body here (the map from the coordinates to the positions "
            r"is invertible), so the scene's potentials fix their force in space, "
            r"$\vec F = -\nabla V$, and it is in $\sum \vec F$."
        )
    elif m.potentials:
        text += (
            " The scene's potentials are not forces on any one body: they enter the balances "
            r"projected on each $\delta q_j$, as $-\partial V/\partial q_j$, and are not in "
            r"$\sum \vec F$."
        )
    constraint_lines = []
    for f in forces:
        lhs = f.label + (" = " + " + ".join(f.parts) if len(f.parts) > 1 else "")
        line = vec_line(lhs, f.vector, f.frame, m, f"constraint force on {f.body}")
        constraint_lines.append(line)
        if f.support is not None:
            tension = f.support[1]
            constraint_lines.append(
                Line(
                    f"tension {f.body}",
                    rf"F_{{T,{sub(f.body)}}} = {to_latex(tension)}",
                    f"F_T_{f.body} = {to_plain(tension)}",
                )
            )
    projected = (
        "Projected on the directions the particle may move (∂r/∂q_j) the balances are "
        "the equations of motion — the same as Lagrange's (D'Alembert, eq. 20). "
    )
    if unknown is None:
        solved_text = projected + (
            "Projected on the others they give the constraint force, here with q̈ from the "
            "equations of motion: the force the constraint must supply."
        )
    else:
        solved_text = projected + unknown
    return [
        Step("newton", "Newton's method: Σ F = m a", text, balances),
        Step("constraint_forces", "Constraint forces", solved_text, constraint_lines),
    ]


#: A free-body diagram's label of an applied force: \vec{F}_{g,\text{bob}}, \vec{M}_{\text{motor}}.
_LABEL = re.compile(r"\\vec\{(?P<letter>\w+)\}_\{(?P<index>.*)\}")
_TEXT = re.compile(r"\\text\{(.*)\}")  # `sub` of a word


def _applied_name(label: str, body: str) -> str:
    """F_g, F_spring, M_motor: the label's letter and subscript without the body's name, in the
    form the constraint forces' names take (F_T, F_N), so that a client needs no LaTeX parser."""
    match = _LABEL.fullmatch(label)
    if match is None:
        return label
    index = match["index"].removesuffix("," + sub(body))
    word = _TEXT.fullmatch(index)
    return f"{match['letter']}_{word[1] if word else index}"


def diagram_forces(d: Derivation) -> list[dict[str, str | None]]:
    """Every force the free-body diagram draws, by body: its name, kind and label there.

    Read from the diagram step's own data, so that /newton and the diagram cannot disagree on a
    name. A scene potential's −∇V is not drawn (it enters through V), so it is not listed."""
    fbd = next(s for s in d.steps if s.id == "fbd")
    out = []
    for drawn in fbd.data["bodies"]:
        body = drawn["body"]
        for f in drawn["forces"]:
            name = _applied_name(f["label"], body)
            out.append(
                {"body": body, "name": name, "kind": f["kind"], "latex": f["label"], "what": None}
            )
        for f in drawn["constraint_forces"]:
            out.append(
                {
                    "body": body,
                    "name": f["name"],
                    "kind": "constraint",
                    "latex": f["label"],
                    "what": f["what"],
                }
            )
    return out


def newton_json(d: Derivation) -> dict[str, Any]:
    """What /api/v1/newton returns: steps, constraint forces, and the agreement with Lagrange."""
    m = d.model
    steps, forces, residual = newton(d)
    lagrange = [lhs - Q for lhs, Q in zip(d.work.eom_lhs, d.work.Q, strict=True)]
    agrees = all(tidy(r - e, m) == 0 for r, e in zip(residual, lagrange, strict=True))
    names = m.plain_vectors
    return {
        "steps": [s.to_json() for s in steps],
        "constraint_forces": [
            {
                "body": f.body,
                "name": f.name,
                "frame": f.frame,
                "unit_vectors": list(names(f.frame)),
                "components": [to_plain(c) for c in f.components],
                "latex": to_latex(f.vector),
                "tension_toward": None if f.support is None else f.support[0],
                "tension": None if f.support is None else to_plain(f.support[1]),
            }
            for f in forces
        ],
        "forces": diagram_forces(d),
        "equations": {
            name: f"{to_plain(r)} = 0" for name, r in zip(m.coordinate_names, residual, strict=True)
        },
        "agrees_with_lagrange": agrees,
        "constraint_forces_unknown": unknown_constraint_forces(m),
    }
