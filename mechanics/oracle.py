"""sympy's own LagrangesMethod/KanesMethod on a scene's bodies: the independent reference.

Tests compare the engine's equations with these, the derive benchmark times them side by side, and
an assignment's keys are checked against them before a student sees a variant
(mechanics/assignments/second_route.py).
The oracle shares only the bodies and the declared loads with the engine; it forms V from the
spec's fields, and the Lagrangian, partial velocities and generalized forces its own (sympy's) way.
"""

from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import KanesMethod, LagrangesMethod, Lagrangian

from mechanics.expr import parse
from mechanics.model import Model
from mechanics.model import T as t


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


def kanes_method(model: Model) -> tuple[sp.Matrix, sp.Matrix]:
    """Kane's M and f with u = q̇ substituted back, so they compare with Lagrange's directly.

    Only for scenes without springs or potentials: Kane's method takes those as forces, which
    would need their gradients — the thing under test.
    """
    u = [sp.Function(f"u{i}")(t) for i in range(len(model.q))]
    kd = [qd - ui for qd, ui in zip(model.qd, u, strict=True)]
    forces = loads(model)
    if model.gravity is not None:
        g, down = model.gravity
        forces += [(b.point, b.mass * g * down) for b in model.bodies]
    km = KanesMethod(model.N, q_ind=model.q, u_ind=u, kd_eqs=kd)
    km.kanes_equations([b.sympy_body for b in model.bodies], forces)
    back = dict(zip(u, model.qd, strict=True))
    back.update({ui.diff(t): qdd for ui, qdd in zip(u, model.qdd, strict=True)})
    return km.mass_matrix.xreplace(back), km.forcing.xreplace(back)
