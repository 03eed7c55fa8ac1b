"""Step 8 (notes I, eq. 3–6 and III): energy or the Jacobi integral, and cyclic momenta."""

from __future__ import annotations

import sympy as sp

from mechanics.expr import to_latex, to_plain
from mechanics.model import Model
from mechanics.model import T as t
from mechanics.steps import Line, Step, Work, _symbols_for, _tidy_symbols, tidy
from mechanics.steps.energy import letter, script_note


def explicit_time(expr: sp.Expr, model: Model) -> bool:
    """Does expr depend on t other than through q(t)? (the coordinates are functions of t)."""
    dummies = {}
    for group in (model.qdd, model.qd, model.q):
        for i, s in enumerate(group):
            dummies[s] = sp.Dummy(f"d{i}")
    return expr.xreplace(dummies).has(t)


def nc_power(model: Model, work: Work) -> sp.Expr:
    """P = Σ_j Q_j^NC q̇_j, the rate at which the non-conservative forces change h (= E when the
    constraints are fixed): dh/dt = P − ∂L/∂t (notes eq. 23). A Lorentz force q v × B has
    Q ≠ 0 but P = 0 (it does no work), so E is conserved as if no force acted."""
    if all(Q == 0 for Q in work.Q):
        return sp.S.Zero
    power = sp.expand(sum(Q * qd for Q, qd in zip(work.Q, model.qd, strict=True)))
    if power != 0 and sp.count_ops(power) <= 400:
        power = tidy(power, model)
    return power


#: At most this many |u| or sign(u) arguments are split by sign (3 cases each: u > 0, u < 0,
#: u = 0); past it, or past MAX_SPLIT_OPS, a power with kinks is not claimed to be 0.
MAX_SIGN_SPLITS = 3
MAX_SPLIT_OPS = 400


def vanishes(power: sp.Expr, model: Model) -> bool:
    """Is the power 0 at every real state? Sound, not complete: True only on a proof.

    sympy cannot simplify sign(ẋ)|ẋ| − ẋ to 0 (it is 0 only for real ẋ), which made a force
    c (sign(ẋ)|ẋ| − ẋ) "do work": a false alarm. So each argument u of abs or sign is split
    into the cases u > 0, u < 0 and u = 0, where |u| = ±u and sign(u) = ±1 or 0 exactly, and
    every case must simplify to 0. A case is reached by a change of variables (u itself as a new
    variable), so that the cases cover every state; where that is not possible (u not real, or
    not linear in any of its symbols with a numeric slope) no claim is made."""
    if power == 0:
        return True
    if not power.has(sp.Abs, sp.sign):  # the caller's simplification was the whole test
        return False
    to_sym, _ = _symbols_for(model)
    e = power.xreplace(to_sym).xreplace({t: sp.Symbol("_t", real=True)})
    return _zero_by_cases(e, MAX_SIGN_SPLITS)


def _zero_by_cases(e: sp.Expr, splits: int) -> bool:
    if sp.count_ops(e) > MAX_SPLIT_OPS:
        return False
    e = sp.expand(_factor_kinks(e))
    kinks = e.atoms(sp.Abs, sp.sign)
    if not kinks:
        return e == 0 or _tidy_symbols(e, (), True)[0] == 0
    if splits == 0:
        return False
    for kink in sorted(kinks, key=sp.default_sort_key):  # one order, one verdict, every run
        u = kink.args[0]
        if u.has(sp.Abs, sp.sign) or u.is_real is not True:  # |u| of a complex u is not ±u
            continue
        solved = _as_variable(u)
        if solved is None:
            continue
        v, rest, slope = solved
        w = sp.Dummy(positive=True)
        cases = ((w - rest) / slope, (-w - rest) / slope, -rest / slope)  # u = w, −w, 0
        return all(_zero_by_cases(e.xreplace({v: c}), splits - 1) for c in cases)
    return False


def _factor_kinks(e: sp.Expr) -> sp.Expr:
    """|ab| = |a| |b|, sgn(ab) = sgn(a) sgn(b), and likewise for integer powers (identities for
    every complex a, b): sgn(ẋ ẏ) becomes two kinks, each in one variable."""

    def split(kink: sp.Expr) -> sp.Expr:
        u = kink.args[0]
        if u.is_Mul:
            return sp.Mul(*(kink.func(f) for f in u.args))
        return kink.func(u.base) ** u.exp

    def splits(x: sp.Expr) -> bool:
        if not isinstance(x, (sp.Abs, sp.sign)):
            return False
        u = x.args[0]
        return u.is_Mul or (u.is_Pow and u.exp.is_integer is True)

    for _ in range(4):  # a product of powers: one level a pass
        e, before = e.replace(splits, split), e
        if e == before:
            break
    return e


def _as_variable(u: sp.Expr) -> tuple[sp.Symbol, sp.Expr, sp.Expr] | None:
    """u = slope·v + rest with slope a nonzero number and rest free of v, or None: then
    v ↦ u is a bijection of the reals and u can stand for v (the other symbols held). A slope
    of ±1, then a rational one, is preferred: a float's reciprocal does not cancel exactly."""
    found = []
    for v in sorted(u.free_symbols, key=str):
        slope = u.diff(v)
        if slope.is_number and slope != 0:
            rest = sp.expand(u - slope * v)
            if not rest.has(v):
                found.append((abs(slope) != 1, not slope.is_Rational, v, rest, slope))
    if not found:
        return None
    *_, v, rest, slope = min(found, key=lambda f: f[:2])
    return v, rest, slope


def conserved_quantities(model: Model, work: Work) -> Step:
    """E = T + V, or the Jacobi integral h, when no force does work (eq. 23); p_j of a cyclic
    coordinate. E, T, V, L and Q are written script where the scene has a parameter of that
    name, as in the energy step, so that "E = T + V" never adds a parameter to energies."""
    E_, T_, V_, L_, Q_ = (letter(model, n) for n in ("E", "T", "V", "L", "Q"))
    lines: list[Line] = []
    found: list[dict] = []
    no_nc = all(Q == 0 for Q in work.Q)
    power_nc = sp.S.Zero if no_nc else nc_power(model, work)
    no_work = no_nc or vanishes(power_nc, model)
    if no_work and not explicit_time(work.L, model):
        h = tidy(sum(qd * p for qd, p in zip(model.qd, work.momenta, strict=True)) - work.L, model)
        E = tidy(work.T + work.V, model)
        if sp.expand(h - E) == 0 or tidy(h - E, model) == 0:
            found.append({"name": "energy", "coordinate": None, "expr": E})
            lines.append(Line("E", f"{E_} = {T_} + {V_} = {to_latex(E)}", f"E = {to_plain(E)}"))
        else:
            found.append({"name": "jacobi", "coordinate": None, "expr": h})
            lines.append(
                Line(
                    "h",
                    rf"h = \sum_j \dot{{q}}_j \frac{{\partial {L_}}}{{\partial "
                    rf"\dot{{q}}_j}} - {L_} = {to_latex(h)}",
                    f"h = {to_plain(h)}",
                )
            )
    for name, qi, p, dq, Qj in zip(
        model.coordinate_names, model.q, work.momenta, work.dL_dq, work.Q, strict=True
    ):
        if Qj == 0 and dq == 0:
            found.append({"name": "momentum", "coordinate": name, "expr": p})
            lines.append(
                Line(
                    f"p_{name}",
                    rf"p_{{{to_latex(qi)}}} = {to_latex(p)}",
                    f"p_{name} = {to_plain(p)}",
                )
            )
    work.conserved = found
    parts = []
    # Q_j^NC: the forces step's Q_j (eq. 31 over all forces) would add −∂V/∂q_j, whose power −dV/dt
    # is already in E = T + V
    power = rf"$\sum_j {Q_}_j^{{NC}} \dot q_j$"
    no_t = f"${L_}$ has no explicit $t$"
    zero, how = "simplifies to 0", "gyroscopic, like a magnetic force"
    if power_nc.has(sp.Abs, sp.sign):  # 0 only case by case: sign(ẋ)|ẋ| = ẋ for real ẋ
        zero = r"is 0 whatever the sign of each argument of $|\cdot|$ and $\operatorname{sgn}$"
        if all(vanishes(Q, model) for Q in work.Q):
            how = "the forces themselves are 0 at every real velocity"
    if any(c["name"] == "energy" for c in found) and not no_nc:
        parts.append(
            f"{no_t}, and the non-conservative forces' power {power} {zero}: they do "
            f"no work ({how}), so ${E_} = {T_} + {V_}$ is conserved "
            rf"($d{E_}/dt = \sum_j {Q_}_j^{{NC}} \dot q_j = 0$, eq. 23)."
        )
    elif any(c["name"] == "energy" for c in found):
        parts.append(
            f"{no_t} and no non-conservative force acts, so ${E_} = {T_} + {V_}$ is "
            rf"conserved ($\Delta {T_} + \Delta {V_} = 0$, notes III)."
        )
    elif any(c["name"] == "jacobi" for c in found):
        parts.append(
            f"The constraints move, so ${T_} + {V_}$ is not conserved, but {no_t}: the Jacobi "
            rf"integral $h = \sum_j \dot q_j\, \partial {L_}/\partial \dot q_j - {L_}$ is"
            + (
                "."
                if no_nc
                else f" (the non-conservative forces' power {power} {zero}: they do no work)."
            )
        )
    elif not no_work:
        if explicit_time(work.L, model):  # dh/dt = P − ∂L/∂t: E is not T + V's whole story
            parts.append(
                "Non-conservative forces do work and the constraints move: the Jacobi "
                rf"integral $h = \sum_j \dot q_j\, \partial {L_}/\partial \dot q_j - {L_}$ "
                rf"changes as $dh/dt = \sum_j {Q_}_j^{{NC}} \dot q_j - \partial {L_}/\partial t$ "
                f"(eq. 23), and neither $h$ nor ${E_}$ is conserved."
            )
        else:
            parts.append(
                "Non-conservative forces do work: "
                rf"$d{E_}/dt = \sum_j {Q_}_j^{{NC}} \dot q_j$, so ${E_}$ changes by "
                r"$W^{NC}$ (eq. 23)."
            )
    else:
        parts.append(
            f"${L_}$ depends explicitly on $t$: neither ${E_}$ nor the Jacobi integral is "
            "conserved."
        )
    if any(c["name"] == "momentum" for c in found):
        parts.append(
            f"A coordinate absent from ${L_}$ (cyclic) has a conserved momentum "
            rf"$p_j = \partial {L_}/\partial \dot q_j$."
        )
    text = " ".join(parts)
    used = [n for n in ("E", "T", "V", "L", "Q") if letter(model, n) in text]
    return Step("conserved", "Conserved quantities", text + script_note(model, *used), lines)
