"""Step 2 (notes I.C, IV.A 2): generalized coordinates, n = 3N − k.

The notes' k (number of constraints) and N (number of particles) are written out as numbers
here: N is also the inertial frame, and k is the spring constant of many scenes."""

from __future__ import annotations

from mechanics.expr import to_latex
from mechanics.model import Model
from mechanics.steps import Line, Step, Work


def generalized_coordinates(model: Model, work: Work) -> Step:
    """Count the degrees of freedom the coordinates leave after the holonomic constraints."""
    particles = sum(1 for b in model.bodies if b.kind == "particle")
    rigid = len(model.bodies) - particles
    free = 3 * particles + 6 * rigid
    n = len(model.q)
    k = free - n
    count = (
        rf"$3 \cdot {particles} = {free}$"
        if not rigid
        else rf"$3 \cdot {particles} + 6 \cdot {rigid} = {free}$"
    )
    # the notes' letter for the count, unless the scene already means something else by k
    taken = set(model.spec.parameters) | set(model.spec.coordinates)
    absorbed = f"$k = {k}$" if "k" not in taken else f"{k}"
    qs = ", ".join(to_latex(q) for q in model.q)
    text = (
        f"{len(model.bodies)} bod{'y' if len(model.bodies) == 1 else 'ies'}: {count} coordinates "
        f"without constraints; the positions below use $n = {n}$ generalized coordinate"
        f"{'s' if n != 1 else ''}, so the scene's geometry absorbs {absorbed} holonomic constraint"
        f"{'s' if k != 1 else ''} "
        rf"(eq. 12). Each position $\vec r_i(q, t)$ satisfies {'it' if k == 1 else 'them'} for "
        "every value of $q$."
    )
    moving = [
        name
        for name, f in model.frames.items()
        if f.angle.has(model.names["t"]) and not any(f.angle.has(q) for q in model.q)
    ]
    if moving:
        text += (
            f" Moving frame(s) {', '.join(moving)} turn at a prescribed rate: "
            "the constraints move (rheonomic)."
        )
    lines = [
        Line(
            "q",
            rf"\mathbf{{q}} = ({qs}), \quad n = {free} - {k} = {n}",
            f"q = ({', '.join(model.coordinate_names)}), n = {n}",
        )
    ]
    return Step(
        "coordinates",
        "Generalized coordinates",
        text,
        lines,
        {"n": n, "k": k, "coordinates": model.coordinate_names, "moving_frames": moving},
    )
