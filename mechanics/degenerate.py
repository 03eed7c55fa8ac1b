"""Refuse a system whose equations of motion do not determine its motion: a singular mass matrix.

A zero mass (or inertia) leaves a coordinate without inertia: M is singular for every state, q̈ is
undefined, and a simulation would grind through NaN until its budget ran out. That is an input
error, reported on the fields that cause it, before anything runs. A mass matrix singular only at
some states (φ at the pole of a sphere) is a property of the coordinates, not an error: runs from
those states are refused by the simulation instead.
"""

from __future__ import annotations

import random

import numpy as np
import sympy as sp

from mechanics.model import T as t
from mechanics.model import physical_limit_errors
from mechanics.spec import SpecError

#: States tried: M must be singular at all of them to blame the parameters.
PROBES = 4


def singular_everywhere(M: sp.Matrix, model, values: dict[str, float]) -> list[int] | None:
    """Is M singular (or not positive definite) at every probed state, at these parameters?

    None when it is not; else the coordinates whose row of M vanishes at every probe (they move
    no mass), possibly none."""
    n = M.shape[0]
    plain = {q: sp.Symbol(f"_q{i}") for i, q in enumerate(model.q)}
    velocities = {qd: sp.Symbol(f"_u{i}") for i, qd in enumerate(model.qd)}
    params = [model.params[k] for k in model.spec.parameters]
    args = [sp.Symbol("_t"), *plain.values(), *velocities.values(), *params]
    exprs = [e.xreplace(velocities).xreplace(plain).xreplace({t: args[0]}) for e in M]
    f = sp.lambdify(args, exprs, modules="numpy")
    rng = random.Random(0)
    positive = set(model.spec.positive_coordinates)
    idle = set(range(n))
    finite = 0
    for _ in range(PROBES):
        q = [
            rng.uniform(0.5, 1.5) if name in positive else rng.uniform(-1.3, 1.3)
            for name in model.coordinate_names
        ]
        u = [rng.uniform(-1, 1) for _ in model.q]
        with np.errstate(all="ignore"):
            try:
                m = np.array(f(rng.uniform(0, 1), *q, *u, *values.values()), dtype=float)
            except (ZeroDivisionError, ValueError, TypeError, OverflowError):
                continue
        m = m.reshape(n, n)
        if not np.all(np.isfinite(m)):
            continue
        finite += 1
        eig = np.linalg.eigvalsh((m + m.T) / 2)
        if eig.min() > 1e-14 * max(abs(eig).max(), 1e-300):
            return None
        idle &= {j for j in range(n) if not np.any(m[j])}
    if not finite:
        raise SpecError([_overflowing(values)])
    return sorted(idle)


def _overflowing(values: dict[str, float]) -> dict[str, str]:
    """M is not a finite double anywhere: name the parameters far from 1 (a units mistake)."""
    far = [k for k, v in values.items() if v and abs(np.log10(abs(v))) > 30]
    return {
        "field": ", ".join(f"parameters.{k}" for k in far) or "parameters",
        "message": "the mass matrix overflows double precision at these parameters: pick units "
        "in which the numbers are nearer 1",
    }


def check_masses(model, values: dict[str, float]) -> None:
    """Every body's mass, evaluated at these parameters, must be a positive number: a mass
    written as an expression ("m - 2", "-1*m") escapes the per-parameter sign checks. The other
    physical limits (stiffness, damping, rest length, gravity ≥ 0, a possible inertia tensor)
    are checked here too, so every caller that takes request parameters (/equilibria beside
    /simulate) refuses the same values."""
    numbers = {model.params[k]: sp.Float(v) for k, v in values.items()}
    errors = []
    for i, b in enumerate(model.bodies):
        try:
            mass = float(b.mass.xreplace(numbers))
        except (TypeError, ValueError):
            continue  # depends on a coordinate or t: the mass matrix check decides
        if not mass > 0 and not mass < 0:  # a negative mass: physical_limit_errors says it
            alone = str(b.mass) if b.mass in model.params.values() else None
            field = f"parameters.{alone}" if alone else f"bodies[{i}].mass"
            errors.append({"field": field, "message": f"must be > 0: {b.name}'s mass is {mass:g}"})
    errors += physical_limit_errors(model, values)
    if errors:
        raise SpecError(errors)


def check_mass_matrix(derivation, values: dict[str, float] | None = None) -> None:
    """Raise SpecError naming the bodies or parameters that leave M singular everywhere, at the
    spec's parameters or the ``values`` a request gives."""
    m, M = derivation.model, derivation.work.mass_matrix
    values = {k: float(v) for k, v in {**m.spec.parameters, **(values or {})}.items()}
    check_masses(m, values)
    idle = singular_everywhere(M, m, values)
    if idle is None:
        return
    used = {str(s) for s in M.free_symbols}
    culprits = [k for k, v in values.items() if k in used and v <= 0]
    massless = [i for i, b in enumerate(m.bodies) if b.mass.is_zero]
    if massless:
        fields = ", ".join(f"bodies[{i}].mass" for i in massless)
        message = "must be > 0: a massless body makes the mass matrix singular for every state"
    elif culprits:
        fields = ", ".join(f"parameters.{k}" for k in culprits)
        said = ", ".join(f"{k} = {values[k]:g}" for k in culprits)
        message = f"must be > 0: with {said} the mass matrix is singular for every state"
    elif idle:
        fields = ", ".join(f"coordinates[{j}]" for j in idle)
        message = (
            f"{', '.join(m.coordinate_names[j] for j in idle)} moves no mass: it appears in no "
            "body's position or orientation, so the mass matrix is singular for every state"
        )
    else:
        fields = "bodies"
        message = (
            "the mass matrix is singular for every state: some coordinate moves no mass "
            "(it appears in no body's position or orientation, or only massless ones)"
        )
    raise SpecError([{"field": fields, "message": message + ", so q̈ is undefined"}])
