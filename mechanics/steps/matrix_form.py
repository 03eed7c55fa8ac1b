"""Step 7: the mass-matrix form M(q, t) q̈ = f(q, q̇, t), and q̈ solved for small systems."""

from __future__ import annotations

import sympy as sp

from mechanics.expr import to_latex, to_plain
from mechanics.model import Model
from mechanics.steps import Line, Step, Work, eq_line, partial, tidy
from mechanics.steps.energy import letter
from mechanics.steps.lagrange import ratio
from mechanics.steps.radicals import held

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
    text = r"Collect the $\ddot q$ terms: $\mathbf M(q, t)\,\ddot q = \mathbf f(q, \dot q, t)$. "
    if "M" in model.spec.parameters or "M" in model.spec.coordinates:
        text += r"(Bold $\mathbf M$ is the mass matrix, not the scene's parameter $M$.) "
    det = None
    if n <= SOLVE_MAX_COORDINATES:
        size = sp.count_ops([*M, *f])
        if size > SOLVE_OPS_BUDGET:
            # bold 𝐌 as in the step's math: a scene may have a mass parameter called M
            work.warnings.append(
                f"q̈ was not solved symbolically: the mass matrix 𝐌 and the forcing 𝐟 have {size} "
                f"operations, past the budget of {SOLVE_OPS_BUDGET}; the simulation solves "
                "𝐌 q̈ = 𝐟 numerically"
            )
        else:
            det = determinant(M, model)
    text += definiteness(det, model, listed=det is not None and len(M) > 1)
    if det is not None and len(M) > 1:
        lines.append(
            Line("det M", rf"\det \mathbf{{M}} = {to_latex(det)}", f"det(M) = {to_plain(det)}")
        )
    if det is not None:
        work.accelerations = solve_accelerations(M, f, model, det)
        for name, qdd, acc in zip(
            model.coordinate_names, model.qdd, work.accelerations, strict=True
        ):
            lines.append(eq_line(f"{name}_ddot", to_latex(qdd), acc, f"{name}_ddot"))
        text += r" Solved for $\ddot q$ (Cramer's rule, each piece simplified):"
    return Step("matrix", "Mass-matrix form", text, lines)


def determinant(M: sp.Matrix, model: Model) -> sp.Expr:
    to, back = held(list(M))  # roots of sums as symbols: det() would simplify inside them
    return tidy(
        M.xreplace(to).det(method="berkowitz").xreplace(back), model, collect_velocities=False
    )


def definiteness(det: sp.Expr | None, model: Model, listed: bool) -> str:
    """What the step may say of M: T ≥ 0 makes it positive semidefinite everywhere, but only a
    nonzero det M makes it definite, and spherical or polar coordinates lose that at their poles
    (a spherical pendulum's det M = l⁴m² sin²θ), where q̈ is not defined."""
    if det is not None and _positive(det, model):
        return (
            r"$\mathbf M$ is symmetric and positive definite at every configuration: "
            r"$\det \mathbf M > 0$ for positive masses and lengths."
        )
    return (
        rf"$\mathbf M$ is symmetric and positive semidefinite (as ${letter(model, 'T')} \ge 0$); "
        r"it is positive "
        r"definite, so that $\ddot q$ is defined, wherever $\det \mathbf M \neq 0$"
        + (" (below)." if listed else ".")
    )


def _positive(det: sp.Expr, model: Model) -> bool:
    """det M > 0 for every real configuration and time, the nonnegative parameters (masses,
    lengths) taken positive: sympy's assumptions decide it, or it is not claimed."""
    t = model.names["t"]
    real = {qi: sp.Dummy(real=True, positive=qi.is_positive or None) for qi in model.q}
    positive = {p: sp.Dummy(positive=True) for p in det.free_symbols if p.is_nonnegative}
    value = det.subs(real).subs({t: sp.Dummy(real=True), **positive})
    return value.is_positive is True


def solve_accelerations(M: sp.Matrix, f: sp.Matrix, model: Model, det: sp.Expr) -> list[sp.Expr]:
    """Cramer's rule with a simplified determinant: small pieces instead of simplify(M⁻¹f)."""
    n = M.shape[0]
    if n == 1:
        return [ratio(f[0], M[0, 0], model)]
    to, back = held([*M, *f])  # roots of sums as symbols: det() would simplify inside them
    out = []
    for i in range(n):
        Mi = M.xreplace(to)
        Mi[:, i] = f.xreplace(to)
        out.append(ratio(Mi.det(method="berkowitz").xreplace(back), det, model))
    return out
