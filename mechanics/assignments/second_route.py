"""sympy's own mechanics on a scene's bodies: the second route that checks a variant's keys.

Copied, with attribution, from mechanics/oracle.py (the tests' independent reference, which the
layer rules keep out of the engine's stages, tests/test_layers.py): V written out from the spec's
fields, the declared loads as sympy's forcelist, and sympy's LagrangesMethod. The route shares
only the model's bodies and declared loads with the derivation; the Lagrangian, the partial
velocities and the generalized forces are formed sympy's way.
"""

from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, Lagrangian

from mechanics.expr import parse
from mechanics.model import Model


def potential(model: Model) -> sp.Expr:
    """V written out from the spec: m g h, ½ k (|d| − ℓ₀)², and the extra potentials."""
    V = sp.S.Zero
    if model.gravity is not None:
        g, down = model.gravity
        for b in model.bodies:
            V += -b.mass * g * b.position.dot(down)
    for spring in model.spec.springs:
        d = model.positions[spring.b] - model.positions[spring.a]
        k = parse(spring.k, model.names)
        l0 = parse(spring.rest_length, model.names)
        V += k * (sp.sqrt(d.dot(d)) - l0) ** 2 / 2
    for _, expr in model.potentials:
        V += expr
    return V


def loads(model: Model) -> list[tuple]:
    """Non-conservative forces as sympy's forcelist: (point, force) and (frame, torque)."""
    out = []
    for load in model.loads:
        if load.kind == "torque":
            body = next(b for b in model.bodies if b.name == load.on)
            out.append((body.frame, load.vector))
        else:
            out.append((model.points[load.on], load.vector))
    return out


def lagranges_method(model: Model) -> LagrangesMethod:
    L = Lagrangian(model.N, *(b.sympy_body for b in model.bodies)) - potential(model)
    lm = LagrangesMethod(L, model.q, forcelist=loads(model), frame=model.N)
    lm.form_lagranges_equations()
    return lm
