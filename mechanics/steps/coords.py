"""Step 2 (notes I.C, IV.A 2): generalized coordinates, n = 3N − k.

The notes' k (number of constraints) and N (number of particles) are written out as numbers
here: N is also the inertial frame, and k is the spring constant of many scenes."""

from __future__ import annotations

import random

import numpy as np
import sympy as sp

from mechanics.expr import to_latex
from mechanics.model import Model
from mechanics.steps import Line, Step, Work, _symbols_for

#: Sample states at which a claim about every state is tested; one seed, one verdict every run.
PROBES = 3


def probe_states(model: Model, count: int = PROBES) -> list[dict[sp.Symbol, sp.Expr]]:
    """Reproducible sample states, as values of the plain symbols of q, q̇ (see `_symbols_for`),
    t and the parameters: each parameter at the spec's value (where the scene's geometry is
    valid), each coordinate off its initial value by a random amount (so that a special start,
    θ = 0 on a hoop, does not hide a term), velocities and t of order 1. A claim that fails at
    one of them fails somewhere: that is a proof; one that holds at all of them is only likely."""
    to_sym, _ = _symbols_for(model)
    rng = random.Random(20261127)
    initial = model.spec.initial or {}
    states = []
    for _ in range(count):
        values: dict[sp.Symbol, sp.Expr] = {
            s: sp.Rational(str(model.spec.parameters[n]))
            for n, s in model.params.items()
            if isinstance(model.spec.parameters.get(n), (int, float))
        }
        values[model.names["t"]] = sp.Rational(rng.randint(200, 2000), 1000)
        for name, q, qd in zip(model.coordinate_names, model.q, model.qd, strict=True):
            try:
                start = float(initial.get(name, 0.0) or 0.0)
            except (TypeError, ValueError):  # an expression: any start will do
                start = 0.0
            if q.is_positive:
                value = (start if start > 0 else 0.5) * rng.uniform(0.7, 1.3)
            else:
                value = start + rng.uniform(-0.5, 0.5)
            values[to_sym[q]] = sp.Rational(round(value * 1000), 1000) or sp.Rational(1, 7)
            values[to_sym[qd]] = sp.Rational(rng.choice([-1, 1]) * rng.randint(300, 1300), 1000)
        states.append(values)
    return states


def constraints_move(model: Model) -> bool:
    """Do the constraints move, not just the frame the coordinates are measured in? Proven at
    a sample state, else False (the caller then says only what is sure).

    They stay put exactly when, at each configuration, some rates q̇ hold every body at rest in
    N (velocity and angular velocity 0): then the frame's turning only relabels positions (a
    puck on a turntable, whose plane z = 0 turns into itself). A bead on a spinning hoop has no
    such rates: its velocity Ω R sin θ across the hoop cannot be cancelled by θ̇."""
    cached = getattr(model, "_constraints_move", None)
    if cached is not None:
        return cached
    to_sym, _ = _symbols_for(model)
    N = model.N
    components = []
    for body in model.bodies:
        rates = [model.velocity(body.name)]
        if body.frame is not None:
            rates.append(body.frame.ang_vel_in(N))
        components += [v.dot(u).xreplace(to_sym) for v in rates for u in (N.x, N.y, N.z)]
    speeds = [to_sym[qd] for qd in model.qd]
    jacobian = [[c.diff(v) for v in speeds] for c in components]
    carried = [c.xreplace(dict.fromkeys(speeds, 0)) for c in components]
    moving = False
    for values in probe_states(model):
        try:
            J = np.array([[complex(e.xreplace(values)) for e in row] for row in jacobian])
            u = np.array([complex(e.xreplace(values)) for e in carried])
        except (TypeError, ValueError, ZeroDivisionError):
            continue
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(u))):
            continue
        if np.max(np.abs(J.imag), initial=0) > 1e-12 or np.max(np.abs(u.imag), initial=0) > 1e-12:
            continue
        J, u = J.real, u.real
        size = float(np.linalg.norm(u))
        if size < 1e-9 * max(float(np.linalg.norm(J)), 1e-300):
            continue
        rates = np.linalg.lstsq(J, -u, rcond=None)[0] if J.size else np.zeros(0)
        left = float(np.linalg.norm(J @ rates + u)) if J.size else size
        if left > 1e-6 * size:
            moving = True
            break
    model._constraints_move = moving
    return moving


def generalized_coordinates(model: Model, work: Work) -> Step:
    """Count the degrees of freedom the coordinates leave after the holonomic constraints."""
    particles = sum(1 for b in model.bodies if b.kind == "particle")
    rigid = len(model.bodies) - particles
    free = 3 * particles + 6 * rigid
    n = len(model.q)
    k = free - n
    count = (
        rf"$3 \cdot {particles} = {free}$"
        if not rigid
        else rf"$3 \cdot {particles} + 6 \cdot {rigid} = {free}$"
    )
    # the notes' letter for the count, unless the scene already means something else by k
    taken = set(model.spec.parameters) | set(model.spec.coordinates)
    absorbed = f"$k = {k}$" if "k" not in taken else f"{k}"
    qs = ", ".join(to_latex(q) for q in model.q)
    text = (
        f"{len(model.bodies)} bod{'y' if len(model.bodies) == 1 else 'ies'}: {count} coordinates "
        f"without constraints; the positions below use $n = {n}$ generalized coordinate"
        f"{'s' if n != 1 else ''}, so the scene's geometry absorbs {absorbed} holonomic constraint"
        f"{'s' if k != 1 else ''} "
        rf"(eq. 12). Each position $\vec r_i(q, t)$ satisfies {'it' if k == 1 else 'them'} for "
        "every value of $q$."
    )
    moving = [
        name
        for name, f in model.frames.items()
        if f.angle.has(model.names["t"]) and not any(f.angle.has(q) for q in model.q)
    ]
    moves = bool(moving) and constraints_move(model)
    if moves:
        text += (
            f" Moving frame(s) {', '.join(moving)} turn at a prescribed rate: "
            "the constraints move (rheonomic)."
        )
    elif moving:  # a turntable's plane turns into itself: only the coordinates' frame moves
        text += (
            f" The coordinates are measured in frame(s) {', '.join(moving)}, turning at a "
            r"prescribed rate: the positions $\vec r_i(q, t)$ depend on $t$ through the frame."
        )
    lines = [
        Line(
            "q",
            rf"\mathbf{{q}} = ({qs}), \quad n = {free} - {k} = {n}",
            f"q = ({', '.join(model.coordinate_names)}), n = {n}",
        )
    ]
    return Step(
        "coordinates",
        "Generalized coordinates",
        text,
        lines,
        {
            "n": n,
            "k": k,
            "coordinates": model.coordinate_names,
            "moving_frames": moving,
            "constraints_move": moves,
        },
    )
