"""Step 6 (notes eq. 35–36, IV.A 5–6): L = T − V and the Euler–Lagrange equation per coordinate."""

from __future__ import annotations

import sympy as sp

from mechanics.expr import to_latex, to_plain
from mechanics.model import Model
from mechanics.steps import Line, Step, Work, d_dt, eq_line, partial, tidy
from mechanics.steps.energy import letter, script_note
from mechanics.steps.radicals import held


def lagrange_equations(model: Model, work: Work) -> Step:
    """d/dt ∂L/∂q̇_j − ∂L/∂q_j = Q_j^NC, shown piece by piece as the notes do."""
    work.L = L = tidy(work.T - work.V, model)
    L_, T_, V_ = (letter(model, x) for x in "LTV")
    lines = [eq_line("L", f"{L_} = {T_} - {V_}", L, "L")]
    work.eom_lhs = []
    for name, qi, qdi, Qj in zip(model.coordinate_names, model.q, model.qd, work.Q, strict=True):
        ql, qdl = to_latex(qi), to_latex(qdi)
        p = tidy(partial(L, qdi, model), model)
        dp = tidy(d_dt(p, model), model)
        dq = tidy(partial(L, qi, model), model)
        lhs = tidy(dp - dq, model, factor_whole=False)  # an EoM reads best term by term
        work.eom_lhs.append(lhs)
        work.momenta.append(p)
        work.dL_dq.append(dq)
        lines += [
            eq_line(
                f"dL/d{name}_dot",
                rf"\frac{{\partial {L_}}}{{\partial {qdl}}}",
                p,
                f"dL/d{name}_dot",
            ),
            eq_line(
                f"d/dt dL/d{name}_dot",
                rf"\frac{{d}}{{dt}}\frac{{\partial {L_}}}{{\partial {qdl}}}",
                dp,
                f"d/dt dL/d{name}_dot",
            ),
            eq_line(f"dL/d{name}", rf"\frac{{\partial {L_}}}{{\partial {ql}}}", dq, f"dL/d{name}"),
            Line(
                f"EoM {name}",
                f"{to_latex(lhs)} = {to_latex(Qj)}",
                f"{to_plain(lhs)} = {to_plain(Qj)}",
            ),
        ]
    text = (
        rf"Form ${L_} = {T_} - {V_}$ (eq. 35). For each coordinate take "
        rf"$\partial {L_}/\partial \dot q_j$, its time derivative and "
        rf"$\partial {L_}/\partial q_j$; the equation of motion is "
        rf"$\frac{{d}}{{dt}}\frac{{\partial {L_}}}{{\partial \dot q_j}} - "
        rf"\frac{{\partial {L_}}}{{\partial q_j}} = Q_j^{{NC}}$ (eq. 36)."
    ) + script_note(model, "L")
    return Step("lagrange", "Lagrangian and Euler–Lagrange equations", text, lines)


def ratio(num: sp.Expr, den: sp.Expr, model: Model) -> sp.Expr:
    """num/den with common polynomial factors cancelled and each side tidied separately.

    Roots of sums (a gravitational potential's) are held as symbols while cancelling: cancel()
    on the roots themselves puts every term over one denominator and took seconds."""
    to, back = held([num, den])
    quotient = sp.factor_terms(num.xreplace(to)) / sp.factor_terms(den.xreplace(to))
    n, d = (x.xreplace(back) for x in sp.fraction(sp.cancel(quotient)))
    return tidy(n, model) / sp.factor(tidy(d, model))
