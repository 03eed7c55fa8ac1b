"""Why a scene's `potentials` leave Newton's constraint forces unknown (issue 23, item 5).

A `potentials` entry is V(q, t): a function on the configuration space, not a field in space.
Its virtual work −∂V/∂q_j is all Lagrange's equations need, but Newton's constraint force
R = m a − ΣF needs the whole applied force on each body, and V(q) fixes only its part along the
directions the bodies may move. Which body it acts on, and how hard it pushes across the
constraints, V(q) cannot say: a zero-length spring pulling a bead on a ring toward a point
presses the bead into the ring, and written as V(θ) that pressing is gone (0 N where the `spring`
gives 7.3 N). So where a potential depends on the coordinates no constraint force is given, and
the reason is said instead, in /newton, in the free-body diagram and in a run's warnings.

Where no constraint acts (every body a particle whose position map q → r has an invertible
Jacobian: a free particle in x, y, z, or in spherical coordinates) V(q) does fix the force in
space, F = −J⁻ᵀ ∂V/∂q, and the constraint force is zero: it is computed, not refused (issue 25:
a free particle in a bowl V = k|r|²/2 was refused with "a pull that presses a bead into its
ring", though nothing constrains it).
"""

from __future__ import annotations

from typing import Any

import sympy as sp
from sympy.physics.vector import Vector

from mechanics.steps import tidy


def coordinate_potentials(model: Any) -> list[str]:
    """Names of the scene's potentials that depend on the coordinates (a V(t) pushes nothing)."""
    return [
        name
        for name, V in model.potentials
        if any(tidy(V.diff(q), model) != 0 for q in model.q if V.has(q))
    ]


def unknown_constraint_forces(model: Any, *, plain: bool = False) -> str | None:
    """Why the constraint forces are not computed, or None when they are.

    One sentence for every place that would otherwise show them: the /newton response, the
    Newton step and the free-body diagram carry its math as LaTeX between $…$ (as every step's
    prose does); a run's warnings, shown as text, take it ``plain``."""
    names = coordinate_potentials(model)
    if not names or potential_forces(model) is not None:
        return None
    which = ", ".join(f"'{n}'" for n in names)
    its = "potential" if len(names) == 1 else "potentials"
    math = _PLAIN if plain else _LATEX
    return (
        f"The constraint forces are not computed: the scene's {its} {which} is given as a "
        f"function of the coordinates, {math['V']}, which fixes only the part of its force "
        f"along the directions the bodies may move (its virtual work {math['dV']}), not which "
        "body it acts on nor how hard it pushes across the constraints (a pull that presses a "
        f"bead into its ring), and the constraint force {math['R']} needs the whole force. "
        f"Newton's equations projected on each {math['dq']} still hold. To have the constraint "
        "forces, write the pull as a spring or as a force on the body it acts on."
    )


_LATEX = {
    "V": "$V(q)$",
    "dV": r"$-\partial V/\partial q_j$",
    "R": r"$\vec R = m\vec a - \sum \vec F$",
    "dq": r"$\delta q_j$",
}
_PLAIN = {"V": "V(q)", "dV": "−∂V/∂q_j", "R": "R = m a − ΣF", "dq": "δq_j"}


def potential_virtual_work(model: Any) -> list[sp.Expr]:
    """∂V/∂q_j of all the scene's potentials together: what they add to Newton's balances
    projected on δq_j (the only part of their force V(q) fixes)."""
    V = sum((e for _, e in model.potentials), sp.S.Zero)
    return [V.diff(q) for q in model.q]


def potential_forces(model: Any) -> dict[str, Vector] | None:
    """−∇V on each body where V(q) fixes it: every body a particle and the stacked Jacobian
    ∂(r₁ … r_N)/∂q square with a determinant that is not identically 0 (no constraint on any
    body), so F = −J⁻ᵀ ∂V/∂q. None where a constraint exists (a bead on a ring: J is 3×1 and
    V(θ) says nothing of the push into the ring) or a body is rigid (V says nothing of a torque
    about which point)."""
    bodies = model.bodies
    if not bodies or any(getattr(b, "frame", None) is not None for b in bodies):
        return None
    if len(model.q) != 3 * len(bodies):
        return None
    rows = [c for b in bodies for c in b.position.to_matrix(model.N)]
    J = sp.Matrix([[c.diff(q) for q in model.q] for c in rows])
    det = tidy(J.det(), model)
    if det == 0 or sp.simplify(det) == 0:
        return None
    grad = sp.Matrix(potential_virtual_work(model))
    force = J.T.LUsolve(-grad)
    axes = (model.N.x, model.N.y, model.N.z)
    out = {}
    for i, b in enumerate(bodies):
        parts = (tidy(force[3 * i + k], model) * u for k, u in enumerate(axes))
        out[b.name] = sum(parts, Vector(0))
    return out
