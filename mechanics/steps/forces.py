"""Step 5 (notes eq. 31, IV.A 4): generalized forces of the non-conservative forces."""

from __future__ import annotations

import sympy as sp

from mechanics.expr import to_latex
from mechanics.model import Model
from mechanics.steps import Step, Work, eq_line, tidy


def generalized_forces(model: Model, work: Work) -> Step:
    """Q_j^NC = Σ F_i·∂v_i/∂q̇_j (+ M·∂ω/∂q̇_j); ∂v/∂q̇ = ∂r/∂q (eq. 17) also for forces of q̇."""
    Q = []
    for qd in model.qd:
        total = sp.S.Zero
        for load in model.loads:
            if load.kind == "torque":
                body = next(b for b in model.bodies if b.name == load.on)
                partial = body.frame.ang_vel_in(model.N).diff(qd, model.N)
            else:
                partial = model.velocity(load.on).diff(qd, model.N)
            total += load.vector.dot(partial)
        Q.append(tidy(total, model))
    work.Q = Q
    lines = [
        eq_line(f"Q_{name}", rf"Q_{{{to_latex(qi)}}}^{{NC}}", Qj, f"Q_{name}")
        for name, qi, Qj in zip(model.coordinate_names, model.q, Q, strict=True)
    ]
    if model.loads:
        text = (
            "Project every non-conservative force on the virtual displacement it works "
            r"through: $Q_j = \sum_i \vec F_i \cdot \partial \vec r_i/\partial q_j$ (eq. 31), and "
            r"torques through $\partial \vec\omega/\partial \dot q_j$."
        )
    else:
        text = "No non-conservative force acts: every $Q_j^{NC} = 0$ and all forces come from $V$."
    return Step("forces", "Generalized forces", text, lines)
