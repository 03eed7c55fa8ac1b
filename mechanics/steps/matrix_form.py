"""Step 7: the mass-matrix form M(q, t) q̈ = f(q, q̇, t), and q̈ solved for small systems."""

from __future__ import annotations

import sympy as sp

from mechanics.expr import to_latex, to_plain
from mechanics.model import Model
from mechanics.steps import Line, Step, Work, eq_line, partial, tidy
from mechanics.steps.lagrange import ratio

#: q̈ is solved symbolically for at most this many coordinates ...
SOLVE_MAX_COORDINATES = 3
#: ... and only while M and f together have at most this many operations (count_ops): Cramer's
#: rule multiplies n entries per term, so the solution grows much faster than M and f. A triple
#: pendulum has 138, a heavy top 79. Past it the simulation solves M q̈ = f numerically.
#: A budget on size, never on the clock: the same spec must give the same derivation.
SOLVE_OPS_BUDGET = 200


def mass_matrix_form(model: Model, work: Work) -> Step:
    """M is linear in q̈ by construction, so M_jk = ∂E_j/∂q̈_k and f = −E|_{q̈=0}."""
    n = len(model.q)
    residual = [lhs - Q for lhs, Q in zip(work.eom_lhs, work.Q, strict=True)]
    M = sp.Matrix(n, n, lambda j, k: tidy(partial(residual[j], model.qdd[k], model), model))
    zero = dict.fromkeys(model.qdd, 0)
    f = sp.Matrix([tidy(-r.xreplace(zero), model) for r in residual])  # q̈ as it is, no chain rule
    work.mass_matrix, work.forcing = M, f
    lines = [
        Line("M", rf"\mathbf{{M}} = {to_latex(M)}", f"M = {to_plain(M.tolist())}"),
        Line("f", rf"\mathbf{{f}} = {to_latex(f)}", f"f = {to_plain(f.T.tolist()[0])}"),
    ]
    text = (
        r"Collect the $\ddot q$ terms: $\mathbf M(q, t)\,\ddot q = \mathbf f(q, \dot q, t)$; "
        r"$\mathbf M$ is symmetric and positive definite."
    )
    if n <= SOLVE_MAX_COORDINATES:
        size = sp.count_ops([*M, *f])
        if size > SOLVE_OPS_BUDGET:
            work.warnings.append(
                f"q̈ was not solved symbolically: M and f have {size} operations, past the "
                f"budget of {SOLVE_OPS_BUDGET}; the simulation solves M q̈ = f numerically"
            )
        else:
            work.accelerations = solve_accelerations(M, f, model)
            for name, qdd, acc in zip(
                model.coordinate_names, model.qdd, work.accelerations, strict=True
            ):
                lines.append(eq_line(f"{name}_ddot", to_latex(qdd), acc, f"{name}_ddot"))
            text += r" Solved for $\ddot q$ (Cramer's rule, each piece simplified):"
    return Step("matrix", "Mass-matrix form", text, lines)


def solve_accelerations(M: sp.Matrix, f: sp.Matrix, model: Model) -> list[sp.Expr]:
    """Cramer's rule with a simplified determinant: small pieces instead of simplify(M⁻¹f)."""
    n = M.shape[0]
    if n == 1:
        return [ratio(f[0], M[0, 0], model)]
    det = tidy(M.det(method="berkowitz"), model, collect_velocities=False)
    out = []
    for i in range(n):
        Mi = M.copy()
        Mi[:, i] = f
        out.append(ratio(Mi.det(method="berkowitz"), det, model))
    return out
