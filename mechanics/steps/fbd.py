"""Step 1 (notes IV.A 1): the free-body diagram — every force on every body, frames, datum."""

from __future__ import annotations

from sympy.physics.vector import Vector

from mechanics.expr import to_latex, to_plain
from mechanics.model import Model
from mechanics.steps import Line, Step, Work, sub, tidy, vec_line


def body_forces(model: Model) -> dict[str, list[tuple[str, str, Vector]]]:
    """(label, kind, vector) of every force acting on each body or point, in N."""
    acting: dict[str, list[tuple[str, str, Vector]]] = {name: [] for name in model.positions}
    if model.gravity is not None:
        g, down = model.gravity
        for b in model.bodies:
            acting[b.name].append((rf"\vec{{W}}_{{{sub(b.name)}}}", "weight", b.mass * g * down))
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


def free_body_diagram(model: Model, work: Work) -> Step:
    """Forces as vectors, constraint forces named (they do no virtual work), frames and datum."""
    acting = body_forces(model)
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
        drawn.append({"body": b.name, "kind": b.kind, "forces": forces})
    constraints = []
    for i, b in enumerate(model.bodies):
        moves = [qi for qi in model.q if b.position.diff(qi, model.N) != Vector(0)]
        free = 3 if b.kind == "particle" else 6
        names = ", ".join(to_latex(qi) for qi in moves) or "nothing"
        constraints.append(
            f"{b.name}: the constraint forces on it are perpendicular to every "
            f"∂r/∂q_j (it moves only with ${names}$), so they do no virtual work"
            if moves
            else f"{b.name}: held fixed by its constraints"
        )
        drawn[i]["free_directions"] = free
    for name, info in model.frames.items():
        w = info.frame.ang_vel_in(model.N)
        lines.append(
            vec_line(
                rf"\vec{{\omega}}_{{{name}/N}}", w, name, model, f"angular velocity of frame {name}"
            )
        )
    datum = "V = 0 with every body at the height of O"
    if model.springs:
        datum += " and every spring at its rest length"
    text = (
        "Draw every force on every body. Weights, springs and potentials are conservative and "
        "enter through V; dampers and applied forces do non-conservative work and enter through "
        f"Q_j. Constraint forces do no virtual work (notes eq. 18). Datum: {datum}."
    )
    return Step(
        "fbd",
        "Free-body diagram",
        text,
        lines,
        {"bodies": drawn, "constraints": constraints, "datum": datum},
    )
