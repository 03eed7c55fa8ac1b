"""Step 8 (notes I, eq. 3–6 and III): energy or the Jacobi integral, and cyclic momenta."""

from __future__ import annotations

import math

import sympy as sp

from mechanics.expr import to_latex, to_plain
from mechanics.model import Model
from mechanics.model import T as t
from mechanics.steps import Line, Step, Work, _symbols_for, _tidy_symbols, d_dt, tidy
from mechanics.steps.coords import constraints_move, probe_states
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


#: Past this size E − h is not matched against the conserved momenta (nothing is said about E).
MAX_DRIVE_OPS = 400


def drive_as_momenta(
    model: Model, work: Work, drive: sp.Expr, cyclic: list[int]
) -> tuple[dict[int, sp.Expr], sp.Expr] | None:
    """E − h = Σ c_i p_i + c_0 over conserved momenta p_i, each c free of q, q̇ and t: then
    E − h is constant along every motion, so E is conserved wherever h is and the drive does no
    work (a turntable turning at Ω about the axis of a cyclic angle φ: E − h = Ω p_φ). Sound, not
    complete: None when no such c is found (it may still exist), and the caller says nothing.

    ``drive`` is E − h = T₁ + 2T₀ (the terms of T linear in and free of q̇, with V); ``cyclic``
    the indices of the coordinates whose momenta are conserved."""
    if not cyclic or sp.count_ops(drive) > MAX_DRIVE_OPS:
        return None
    to_sym, _ = _symbols_for(model)
    time = sp.Symbol("_t", real=True)

    def plain(e: sp.Expr) -> sp.Expr:
        return sp.expand(e.xreplace(to_sym).xreplace({t: time}))

    coefficients = [sp.Dummy(f"c{i}") for i in cyclic]
    momenta = [plain(work.momenta[i]) for i in cyclic]
    rest = plain(drive) - sum((c * p for c, p in zip(coefficients, momenta, strict=True)), 0)
    speeds = [to_sym[qd] for qd in model.qd]
    try:
        found = sp.solve([sp.expand(rest.diff(v)) for v in speeds], coefficients, dict=True)
    except (NotImplementedError, ValueError):
        return None
    state = {*speeds, *(to_sym[q] for q in model.q), time}
    for solution in found:
        c = [sp.simplify(solution.get(x, x)) for x in coefficients]
        if any(x.free_symbols & (state | set(coefficients)) for x in c):
            continue
        constant = sp.expand(rest.xreplace(dict(zip(coefficients, c, strict=True))))
        if all(_is_zero(constant.diff(v)) for v in state):
            return dict(zip(cyclic, c, strict=True)), _simplest(
                constant.xreplace(_zero_state(model, time))
            )
    return None


def _zero_state(model: Model, time: sp.Symbol) -> dict:
    to_sym, _ = _symbols_for(model)
    return {to_sym[x]: 0 for x in (*model.q, *model.qd)} | {time: 0}


def _simplest(e: sp.Expr) -> sp.Expr:
    return sp.simplify(e) if sp.count_ops(e) <= MAX_DRIVE_OPS else e


def _is_zero(e: sp.Expr) -> bool:
    """0 at every state, by expansion, the trig pass, then simplify (within the size budget)."""
    e = sp.expand(e)
    if e == 0:
        return True
    if sp.count_ops(e) > MAX_DRIVE_OPS:
        return False
    return _tidy_symbols(e, (), True)[0] == 0 or sp.simplify(e) == 0


def drive_works_somewhere(model: Model, work: Work, drive: sp.Expr) -> bool:
    """Is d(E − h)/dt ≠ 0 at a sample state, q̈ taken from the equations of motion? A proof that
    the drive does work (where h is conserved, dE/dt = d(E − h)/dt): T + V is then not conserved
    (a bead on a spinning hoop). False when no sample shows it: then nothing is claimed."""
    to_sym, _ = _symbols_for(model)
    rate = d_dt(drive, model).xreplace(to_sym)
    if rate == 0:
        return False
    terms = (
        sp.Add.make_args(sp.expand(rate)) if sp.count_ops(rate) <= 4 * MAX_DRIVE_OPS else (rate,)
    )
    accelerations = [to_sym[x] for x in model.qdd]
    for values in probe_states(model):
        try:
            if work.accelerations is not None:
                qdd = [_expr(a).xreplace(to_sym).xreplace(values) for a in work.accelerations]
            else:
                M = work.mass_matrix.xreplace(to_sym).xreplace(values).evalf(30)
                f = work.forcing.xreplace(to_sym).xreplace(values).evalf(30)
                qdd = list(M.LUsolve(f))
            at = values | dict(zip(accelerations, qdd, strict=True))
            parts = [complex(sp.N(term.xreplace(at), 30)) for term in terms]
        except (TypeError, ValueError, ArithmeticError, sp.SympifyError):
            continue  # no number here (a domain's edge, a singular M): another sample may tell
        if not all(math.isfinite(p.real) and abs(p.imag) <= 1e-12 * (1 + abs(p)) for p in parts):
            continue
        total, scale = sum(p.real for p in parts), sum(abs(p) for p in parts)
        if scale > 0 and abs(total) > 1e-8 * scale:
            return True
    return False


def _expr(a: object) -> sp.Basic:
    """A solved acceleration as sympy: the engine's own expressions (never text; a plain 0 may
    come as an int)."""
    if isinstance(a, sp.Basic):
        return a
    if isinstance(a, int):
        return sp.Integer(a)
    return sp.Float(float(a))


def drive_rate_vanishes(model: Model, work: Work, drive: sp.Expr) -> bool:
    """Does d(E − h)/dt, q̈ taken from the solved equations of motion, simplify to 0? A proof
    that E − h is constant along every motion where no conserved momentum shows it (a puck on a
    turntable in Cartesian coordinates: E − h = Ω L_z, conserved by the spring's symmetry).
    False past the size budget or without a symbolic solution."""
    if work.accelerations is None or sp.count_ops(drive) > MAX_DRIVE_OPS:
        return False
    to_sym, _ = _symbols_for(model)
    solved = {
        to_sym[x]: _expr(a).xreplace(to_sym)
        for x, a in zip(model.qdd, work.accelerations, strict=True)
    }
    rate = d_dt(drive, model).xreplace(to_sym).xreplace(solved)
    if sp.count_ops(rate) > 4 * MAX_DRIVE_OPS:
        return False
    numerator = sp.expand(sp.numer(sp.together(sp.expand(rate))))
    return numerator == 0 or _is_zero(numerator)


def conserved_quantities(model: Model, work: Work) -> Step:
    """E = T + V, or the Jacobi integral h, when no force does work (eq. 23); p_j of a cyclic
    coordinate. E, T, V, L and Q are written script where the scene has a parameter of that
    name, as in the energy step, so that "E = T + V" never adds a parameter to energies.

    Where the coordinates are measured in a moving frame, E − h = T₁ + 2T₀ ≠ 0 and what is said
    of E rests on a proof either way: E is conserved too when E − h is a constant combination
    of conserved momenta (a turntable: E = h + Ω p_φ), not conserved when d(E − h)/dt ≠ 0 at a
    sample state (a spinning hoop); otherwise nothing is said about E."""
    E_, T_, V_, L_, Q_ = (letter(model, n) for n in ("E", "T", "V", "L", "Q"))
    lines: list[Line] = []
    found: list[dict] = []
    no_nc = all(Q == 0 for Q in work.Q)
    power_nc = sp.S.Zero if no_nc else nc_power(model, work)
    no_work = no_nc or vanishes(power_nc, model)
    explicit = explicit_time(work.L, model)
    cyclic = [
        j for j, (dq, Qj) in enumerate(zip(work.dL_dq, work.Q, strict=True)) if Qj == 0 and dq == 0
    ]
    # what the drive that moves the coordinates' frame does: "none" (E − h constant), "some"
    # (shown at a state), "unknown"; None where L has explicit t (then dh/dt ≠ P_NC)
    drive_work: str | None = None
    combination: tuple[dict[int, sp.Expr], sp.Expr] | None = None
    steady: sp.Expr | None = None  # E − h, shown constant by its rate
    if not explicit:
        h_raw = sum(qd * p for qd, p in zip(model.qd, work.momenta, strict=True)) - work.L
        drive = sp.expand(work.T + work.V - h_raw)
        if drive == 0 or tidy(drive, model) == 0:
            drive_work = "none"
        else:
            combination = drive_as_momenta(model, work, drive, cyclic)
            if combination is not None:
                drive_work = "none"
            elif drive_works_somewhere(model, work, drive):
                drive_work = "some"
            elif drive_rate_vanishes(model, work, drive):
                drive_work, steady = "none", tidy(drive, model)
            else:
                drive_work = "unknown"
    E_is_h = drive_work == "none" and combination is None and steady is None
    E = tidy(work.T + work.V, model) if no_work and drive_work == "none" else None
    h = None
    if no_work and not explicit:
        if E_is_h:
            found.append({"name": "energy", "coordinate": None, "expr": E})
            lines.append(Line("E", f"{E_} = {T_} + {V_} = {to_latex(E)}", f"E = {to_plain(E)}"))
        else:
            h = tidy(h_raw, model)
            found.append({"name": "jacobi", "coordinate": None, "expr": h})
            lines.append(
                Line(
                    "h",
                    rf"h = \sum_j \dot{{q}}_j \frac{{\partial {L_}}}{{\partial "
                    rf"\dot{{q}}_j}} - {L_} = {to_latex(h)}",
                    f"h = {to_plain(h)}",
                )
            )
    momentum_lines = []
    for name, qi, p, dq, Qj in zip(
        model.coordinate_names, model.q, work.momenta, work.dL_dq, work.Q, strict=True
    ):
        if Qj == 0 and dq == 0:
            found.append({"name": "momentum", "coordinate": name, "expr": p})
            momentum_lines.append(
                Line(
                    f"p_{name}",
                    rf"p_{{{to_latex(qi)}}} = {to_latex(p)}",
                    f"p_{name} = {to_plain(p)}",
                )
            )
    lines += momentum_lines
    offset = None  # E − h written with the momenta' names: Ω p_φ
    if combination is not None:
        coefficients, constant = combination
        names = model.coordinate_names
        offset = (
            sum((c * sp.Symbol(f"p_{names[j]}") for j, c in coefficients.items()), sp.S.Zero)
            + constant
        )
        if no_work:
            found.append({"name": "energy", "coordinate": None, "expr": E})
            lines.append(
                Line(
                    "E",
                    f"{E_} = {T_} + {V_} = h + {to_latex(offset)} = {to_latex(E)}",
                    f"E = h + {to_plain(offset)} = {to_plain(E)}",
                )
            )
    if steady is not None and no_work:
        found.append({"name": "energy", "coordinate": None, "expr": E})
        lines.append(Line("E", f"{E_} = {T_} + {V_} = {to_latex(E)}", f"E = {to_plain(E)}"))
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
    jacobi = rf"the Jacobi integral $h = \sum_j \dot q_j\, \partial {L_}/\partial \dot q_j - {L_}$"
    no_work_nc = (
        "." if no_nc else f" (the non-conservative forces' power {power} {zero}: they do no work)."
    )
    offset_words, total = None, ""
    if offset is not None:  # h and each p_j are conserved, so is their sum with constant weights
        offset_words = (
            f"${E_} - h = {to_latex(offset)}$, a constant combination of conserved momenta"
        )
        total = f" = h + {to_latex(offset)}"
    elif steady is not None:
        offset = steady
        offset_words = (
            f"${E_} - h = {to_latex(steady)}$ is constant along every motion (its rate, with "
            r"$\ddot q$ from the equations of motion, simplifies to 0)"
        )
    if E_is_h and no_work and not no_nc:
        parts.append(
            f"{no_t}, and the non-conservative forces' power {power} {zero}: they do "
            f"no work ({how}), so ${E_} = {T_} + {V_}$ is conserved "
            rf"($d{E_}/dt = \sum_j {Q_}_j^{{NC}} \dot q_j = 0$, eq. 23)."
        )
    elif E_is_h and no_work:
        parts.append(
            f"{no_t} and no non-conservative force acts, so ${E_} = {T_} + {V_}$ is "
            rf"conserved ($\Delta {T_} + \Delta {V_} = 0$, notes III)."
        )
    elif offset is not None and no_work:
        parts.append(
            f"{no_t}: {jacobi} is conserved{no_work_nc[:-1] if no_work_nc != '.' else ''}. "
            f"The coordinates are measured in a moving frame, so $h$ is not ${T_} + {V_}$, but "
            f"{offset_words}, so ${E_} = {T_} + {V_}{total}$ is conserved too: the drive "
            "that turns the frame does no work."
        )
    elif drive_work == "some" and no_work:
        moved = (
            "The constraints move"
            if constraints_move(model)
            else rf"The drive that moves the coordinates' frame does work ($d({E_} - h)/dt \ne 0$)"
        )
        parts.append(
            f"{moved}, so ${T_} + {V_}$ is not conserved, but {no_t}: {jacobi} is{no_work_nc}"
        )
    elif drive_work == "unknown" and no_work:
        parts.append(
            f"{no_t}: {jacobi} is conserved{no_work_nc[:-1] if no_work_nc != '.' else ''}. "
            f"It is not ${T_} + {V_}$ here, since the positions depend on $t$ through a moving "
            "frame."
        )
    elif not no_work:
        if explicit:  # dh/dt = P − ∂L/∂t: E is not T + V's whole story
            parts.append(
                "Non-conservative forces do work and the constraints move: the Jacobi "
                rf"integral $h = \sum_j \dot q_j\, \partial {L_}/\partial \dot q_j - {L_}$ "
                rf"changes as $dh/dt = \sum_j {Q_}_j^{{NC}} \dot q_j - \partial {L_}/\partial t$ "
                f"(eq. 23), and neither $h$ nor ${E_}$ is conserved."
            )
        elif E_is_h:
            parts.append(
                "Non-conservative forces do work: "
                rf"$d{E_}/dt = \sum_j {Q_}_j^{{NC}} \dot q_j$, so ${E_}$ changes by "
                r"$W^{NC}$ (eq. 23)."
            )
        elif offset is not None:
            parts.append(
                f"Non-conservative forces do work: {jacobi} changes as "
                rf"$dh/dt = \sum_j {Q_}_j^{{NC}} \dot q_j$, so $h$ changes by $W^{{NC}}$; "
                f"{offset_words}, so ${E_} = {T_} + {V_}$ changes by $W^{{NC}}$ too "
                rf"($\Delta {T_} + \Delta {V_} = W^{{NC}}$, eq. 23): the drive that turns the "
                "frame does no work."
            )
        else:
            parts.append(
                f"Non-conservative forces do work: {jacobi} changes as "
                rf"$dh/dt = \sum_j {Q_}_j^{{NC}} \dot q_j$, so $h$ changes by $W^{{NC}}$, "
                f"and ${E_} = {T_} + {V_}$ by $W^{{NC}}$ plus the work of the drive that moves "
                rf"the coordinates' frame: $\Delta {T_} + \Delta {V_} = W^{{NC}} + "
                r"W_{\mathrm{drive}}$ (eq. 23 with the drive's work added)."
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
    data = {} if drive_work is None else {"drive_work": drive_work}
    return Step("conserved", "Conserved quantities", text + script_note(model, *used), lines, data)
