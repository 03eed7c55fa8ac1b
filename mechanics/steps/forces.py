"""Step 5 (notes eq. 31, IV.A 4): generalized forces of the non-conservative forces."""

from __future__ import annotations

import sympy as sp

from mechanics.expr import to_latex
from mechanics.model import Model
from mechanics.steps import Step, Work, eq_line, partial, tidy
from mechanics.steps.energy import letter, script_note


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
    Q_, V_ = letter(model, "Q"), letter(model, "V")
    L_, T_ = letter(model, "L"), letter(model, "T")
    # the plain copy says NC as the LaTeX does: a bare Q_x = 0 reads as the whole Q_x
    Q_plain = "Q" if Q_ == "Q" else "script_Q"
    lines = [
        eq_line(f"Q_{name}", rf"{Q_}_{{{to_latex(qi)}}}^{{NC}}", Qj, f"{Q_plain}_{name}^NC")
        for name, qi, Qj in zip(model.coordinate_names, model.q, Q, strict=True)
    ]
    # Eq. 31 sums every force, weights and springs too; those are in V already, and counted
    # again here they would act twice in the Lagrange equations.
    if model.loads:
        text = (
            f"The conservative forces (weights, springs, potentials) are already in ${V_}$, so "
            "only the non-conservative ones are projected here, each on the virtual "
            "displacement it works through: "
            rf"${Q_}_j^{{NC}} = \sum_i \vec F_i^{{NC}} \cdot \partial \vec r_i/\partial q_j$, "
            r"and torques through $\partial \vec\omega/\partial \dot q_j$ (eq. 31 over these "
            "forces alone). Eq. 31 over all the forces would give "
            rf"${Q_}_j = {Q_}_j^{{NC}} - \partial {V_}/\partial q_j$; the conservative part "
            rf"$-\partial {V_}/\partial q_j$ enters through ${L_} = {T_} - {V_}$ instead."
        )
    else:
        text = (
            f"No non-conservative force acts: every ${Q_}_j^{{NC}} = 0$. The generalized "
            rf"forces of eq. 31 are then all conservative, ${Q_}_j = -\partial {V_}/\partial q_j$"
            f"{_conservative_example(model, work, Q_, V_)}, and enter through ${V_}$, not here."
        )
    return Step("forces", "Generalized forces", text + script_note(model, "Q"), lines)


def _conservative_example(model: Model, work: Work, Q_: str, V_: str) -> str:
    """', here Q_x = −∂V/∂x = g(m₁ − m₂)' for one coordinate: the sentence beside Q_x^NC = 0
    then shows that the whole Q_x is not 0 (an Atwood machine's is the weights' difference)."""
    if len(model.q) != 1:
        return ""
    q = model.q[0]
    conservative = tidy(-partial(work.V, q, model), model)
    if sp.count_ops(conservative) > 12:
        return ""
    x = to_latex(q)
    return (
        rf", here ${Q_}_{{{x}}} = -\partial {V_}/\partial {x} = {to_latex(conservative)}$"
        rf" while ${Q_}_{{{x}}}^{{NC}} = 0$"
    )
