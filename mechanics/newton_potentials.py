"""Why a scene's `potentials` leave Newton's constraint forces unknown (issue 23, item 5).

A `potentials` entry is V(q, t): a function on the configuration space, not a field in space.
Its virtual work −∂V/∂q_j is all Lagrange's equations need, but Newton's constraint force
R = m a − ΣF needs the whole applied force on each body, and V(q) fixes only its part along the
directions the bodies may move. Which body it acts on, and how hard it pushes across the
constraints, V(q) cannot say: a zero-length spring pulling a bead on a ring toward a point
presses the bead into the ring, and written as V(θ) that pressing is gone (0 N where the `spring`
gives 7.3 N). So where a potential depends on the coordinates no constraint force is given, and
the reason is said instead, in /newton, in the free-body diagram and in a run's warnings.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

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
    if not names:
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
