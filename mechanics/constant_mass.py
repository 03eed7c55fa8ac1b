"""Masses and inertias must be constant: a spec whose mass varies is refused (issue 23, item 6).

Lagrange's equations d/dt ∂L/∂q̇ − ∂L/∂q = Q come from d'Alembert's principle for bodies whose
mass does not change. Given m(t), T = ½ m ẋ² turns them into d(m ẋ)/dt = F, which is not
Galilean invariant: the term ṁ ẋ depends on the observer's frame (a leaking cart would be pushed
forward by −ṁ ẋ in one frame and not in another). The motion of a body that gains or loses mass
depends on where that mass goes and at what velocity (the rocket equation m v̇ = F + ṁ u, u the
velocity of the ejected mass relative to the body), which a spec cannot say. A mass depending on
the coordinates is the same problem met along the path, and a central inertia tensor depending
on t or q is a body changing shape or losing mass. So they are refused, naming the field.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from mechanics.expr import ExprError, parse

WHY = (
    "Lagrange's equations here need constant masses: with a mass m({0}) the kinetic energy "
    "½ m v² puts ṁ v into the equations (d(m v)/dt where Newton has m dv/dt), a term that "
    "depends on the observer's frame (a leaking cart would be pushed forward by −ṁ v), while a "
    "body gaining or losing mass moves as the mass it exchanges dictates (the rocket equation "
    "m v̇ = F + ṁ u, u that mass's velocity relative to the body), which a spec cannot say. "
    "Give a constant (a number or parameters)"
)
WHY_INERTIA = (
    "a rigid body's central inertia in its own frame is constant; one that depends on {0} "
    "belongs to a body changing shape or mass, for which Lagrange's equations here (constant "
    "masses and inertias) do not hold. Give a constant (a number or parameters)"
)


def _names(spec: Any) -> tuple[dict[str, sp.Symbol], set[sp.Symbol]]:
    """Symbols for t, the coordinates and the parameters, and which of them vary."""
    varying = {name: sp.Symbol(name) for name in ["t", *spec.coordinates]}
    table = {**{p: sp.Symbol(p) for p in spec.parameters}, **varying}
    return table, set(varying.values())


def _varies(value: Any, table: dict[str, sp.Symbol], varying: set[sp.Symbol]) -> list[str]:
    """The names among t and the coordinates a value depends on (none when it cannot be read:
    the model builder reports that, with its field)."""
    if not isinstance(value, str):
        return []
    try:
        e = parse(value, table)
    except ExprError:
        return []
    return sorted(str(s) for s in e.free_symbols & varying)


def variable_mass_errors(spec: Any) -> list[dict[str, str]]:
    """A 422 entry per body mass or inertia entry that depends on t or the coordinates."""
    table, varying = _names(spec)
    errors = []
    for i, b in enumerate(spec.bodies):
        on = _varies(b.mass, table, varying)
        if on:
            errors.append(
                {
                    "field": f"bodies[{i}].mass",
                    "message": f"must be constant, not a function of {', '.join(on)}: "
                    + WHY.format(", ".join(on)),
                }
            )
        if b.inertia is None:
            continue
        for key in ("ixx", "iyy", "izz", "ixy", "iyz", "izx"):
            on = _varies(getattr(b.inertia, key), table, varying)
            if on:
                errors.append(
                    {
                        "field": f"bodies[{i}].inertia.{key}",
                        "message": f"must be constant, not a function of {', '.join(on)}: "
                        + WHY_INERTIA.format(", ".join(on)),
                    }
                )
    return errors
