"""Where the quadratic part of the potential is flat: the higher-order test, and its words.

K singular in a direction that is no free coordinate used to end in "the linear test cannot
decide" even where the answer is plain: a mass between two springs of rest length half the
span, moved across them (V ∝ y⁴), or a bead on a hoop spun at exactly Ω² = g/R (V_eff ∝ θ⁴),
sits in a strict minimum and is Lyapunov stable (Lagrange–Dirichlet). Along each flat direction
the stiff coordinates relax to their balance and the force along it decides
(``equilibrium_stability.along_flat``): a level direction is a family of equilibria (counted
with the free ones), a rising one a minimum, a falling one no minimum. Numbers only: the
caller passes the forces and the stiffness as functions of the kept coordinates.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mechanics import equilibrium_stability as stability


@dataclass
class FlatReport:
    """``level``: how many flat directions are a family of equilibria; ``shapes``: what V does
    along the others; ``directions``: those directions (columns over the kept coordinates)."""

    level: int
    shapes: list[stability.Flat]
    directions: np.ndarray


def flat_report(
    M: np.ndarray,
    K: np.ndarray,
    keep: list[int],
    force: Callable[[np.ndarray], np.ndarray],
    stiffness: Callable[[np.ndarray], np.ndarray],
    q0: np.ndarray,
    length: float,
) -> FlatReport | None:
    """The higher-order test along every flat direction of K among the coordinates ``keep``
    (the non-free ones); None when K has none (the linear test decides)."""
    flat, stiff = stability.flat_directions(M, K, keep)
    if not flat.shape[1]:
        return None
    kappa = max(float(np.max(np.abs(K))), 1e-300)
    if kappa <= 1e-12 * max(1.0, float(np.max(np.abs(M)))):  # K = 0: the forces' own size
        kappa = 0.0
    shapes = [
        stability.along_flat(force, stiffness, q0, flat[:, i], stiff, length, kappa)
        for i in range(flat.shape[1])
    ]
    level = sum(1 for f in shapes if f.shape == "level")
    kept = [i for i, f in enumerate(shapes) if f.shape != "level"]
    return FlatReport(level, [shapes[i] for i in kept], flat[:, kept])


def _direction(u: np.ndarray, names: list[str]) -> str:
    """δq ∝ (…) over the coordinates it moves, as LaTeX inside $…$."""
    u = u / np.max(np.abs(u))
    parts = [(n, x) for n, x in zip(names, u, strict=True) if abs(x) > 1e-9]
    if len(parts) == 1:
        return f"\\delta {parts[0][0]}"
    inner = ", ".join(f"{x:.3g}" for x in u)
    return f"\\delta q \\propto ({inner})"


def _power_words(order: int) -> str:
    return f" like $|s|^{{{order}}}$" if order else ""


def conserved(potential: str) -> str:
    """The conserved quantity that bounds the motion by the ``potential`` named: E = T + V for
    a plain potential; in a steadily driven scene (a hoop spun at Ω, a support moved at v) E is
    not conserved (the drive does work) but the Jacobi integral h = T₂ + V − T₀ is, and it is
    what the effective potential V − T₀ stands in (issue 25, item 5)."""
    if potential.startswith("effective"):
        return (
            "the Jacobi integral $h = T_2 + V - T_0$, conserved in the steadily driven scene "
            "where $E = T + V$ is not,"
        )
    return "$E = T + V$"


def amend(
    kind: str,
    reason: str,
    report: FlatReport | None,
    names: list[str],
    shown: str,
    single: bool,
    potential: str,
) -> tuple[str, str]:
    """The verdict once the flat directions are judged. ``kind``/``reason``: the linear test's
    (with the level directions counted as free); ``single``: the flat direction is the system's
    only non-free coordinate (then V falling on a side is instability, by energy alone);
    ``potential``: 'potential' or 'effective potential (…)'."""
    if report is None or not report.shapes or kind != "marginal":
        return kind, reason
    if len(report.shapes) > 1:
        falls = [f for f in report.shapes if f.shape == "falls"]
        if not falls:
            return kind, reason + (
                "; the higher-order test along each flat direction alone does not settle a "
                "minimum over all of them (a quartic can rise on every axis and fall between), "
                "so it cannot decide"
            )
    f = report.shapes[0] if len(report.shapes) == 1 else falls[0]
    where = _direction(report.directions[:, report.shapes.index(f)], names)
    flat = (
        f"$\\mathbf K$ is singular along ${where}$ (the quadratic part of the {potential} "
        "vanishes there, so the linear test alone is silent); the higher-order test, with "
        "the other coordinates at their balance, "
    )
    if f.shape == "rises":
        return "stable", (
            flat + f"finds the force along it restoring on both sides: the {potential} rises"
            f"{_power_words(f.order)}, a strict minimum, so the equilibrium is stable "
            f"(Lagrange–Dirichlet: {conserved(potential)} cannot carry the motion over the "
            "rise). Along that "
            "direction the oscillation is not harmonic (its period depends on the amplitude), "
            f"which the zero eigenvalues of the linearization stand for (the motion's "
            f"eigenvalues {shown})"
        )
    if f.shape == "falls":
        side = {1: f"on the side ${where} > 0$", -1: f"on the side ${where} < 0$"}.get(
            f.side, "on both sides"
        )
        text = flat + f"finds the {potential} falling{_power_words(f.order)} {side}: no minimum"
        if single:
            return "unstable", text + (
                ", and released at rest beside it the system moves away down the slope: "
                f"unstable (the motion's eigenvalues {shown}, all on the axis, do not show it)"
            )
        return "marginal", text + (
            ", so Lagrange–Dirichlet does not hold it; instability is expected but the "
            f"test does not prove it: cannot decide (the motion's eigenvalues {shown})"
        )
    return kind, reason + (
        "; the higher-order test along it is lost in round-off or its sides disagree, so it "
        "cannot decide either"
    )


def flat_at(
    at_rest: Callable[..., list],
    forces: Callable[..., list],
    q0: list[float],
    numbers: list[float],
    idx: list[int],
    keep: list[int],
    M: np.ndarray,
    C: np.ndarray,
    K: np.ndarray,
) -> FlatReport | None:
    """``flat_report`` from the scene's numpy functions of (q, parameters): ``at_rest`` gives
    (M, K, C), ``forces`` f at rest. Only where a potential can stand behind the forces at rest
    (K symmetric) and the velocity-linear ones take no energy in (C's symmetric part ≥ 0):
    elsewhere a rise of V proves nothing."""
    size = max(float(np.max(np.abs(K))), 1e-300)
    if np.max(np.abs(K - K.T)) > 1e-9 * size:
        return None
    Cs = (C + C.T) / 2
    if Cs.size and np.min(np.linalg.eigvalsh(Cs)) < -1e-9 * max(1.0, float(np.max(np.abs(C)))):
        return None
    n = len(q0)
    base = np.asarray(q0, dtype=float)

    def full(x: np.ndarray) -> list[float]:
        q = base.copy()
        q[idx] = x
        return list(q)

    def force(x: np.ndarray) -> np.ndarray:
        return np.array(forces(*full(x), *numbers), dtype=float).reshape(n)[idx]

    def stiffness(x: np.ndarray) -> np.ndarray:
        k = np.array(at_rest(*full(x), *numbers)[1], dtype=float).reshape(n, n)
        return k[np.ix_(idx, idx)]

    with np.errstate(all="ignore"):
        return flat_report(M, K, keep, force, stiffness, base[idx], 1.0)


#: How a verdict at a point where no coordinate carries inertia begins (the caller's warning
#: for a point that is not held there reads it).
SINGULAR = "No coordinate carries inertia here"


def singular_point(
    at_rest: Callable[..., list] | None,
    forces: Callable[..., list] | None,
    q0: list[float],
    numbers: list[float],
) -> tuple[str, str, bool]:
    """The verdict where the mass matrix vanishes (∂r/∂q = 0: the cusp of a cycloid, x = s³),
    and whether the caller must still check that the forces vanish beside the point.

    The coordinates are singular there, not the body weightless, and the linearization says
    nothing. In the configuration the potential still decides for one coordinate: where it
    rises on both sides (a smooth minimum, or the notch of a cusp pointing down, where the force
    along the wire points into the cusp from both sides) E = T + V with T ≥ 0 keeps the motion
    in the well: stable (Lagrange–Dirichlet needs no inertia). Where it falls on a side, a body
    released there at rest runs away: unstable, if the point is an equilibrium at all (at the
    cusp at the top of a cycloid's arch gravity pulls along the vertical wire right up to it:
    not one, which the caller's check finds). Otherwise no verdict, with the reason. Never
    'stable because no coordinate carries inertia'."""
    head = (
        f"{SINGULAR}: the mass matrix vanishes, because the position does not move to first "
        "order in the coordinates ($\\partial \\mathbf r/\\partial q = 0$, a cusp or a "
        "stationary point of the parametrization), so the coordinates are singular here and "
        "the linearization says nothing"
    )
    if at_rest is None or forces is None or len(q0) != 1:
        return "marginal", head + "; no verdict in these coordinates", False
    base = np.asarray(q0, dtype=float)

    def force(x: np.ndarray) -> np.ndarray:
        return np.array(forces(*x, *numbers), dtype=float).reshape(1)

    def stiffness(x: np.ndarray) -> np.ndarray:
        return np.array(at_rest(*x, *numbers)[1], dtype=float).reshape(1, 1)

    with np.errstate(all="ignore"):
        shape = stability.along_flat(force, stiffness, base, np.ones(1), np.zeros((1, 0)), 1.0, 0.0)
    if shape.shape == "rises":
        return (
            "stable",
            head
            + (
                "; but along the path the potential rises on both sides"
                f"{_power_words(shape.order)} (a minimum in the configuration, or a notch where "
                "the force points into the point from both sides), and E = T + V with T ≥ 0 keeps "
                "the motion below the energy it starts with: stable (Lagrange–Dirichlet needs no "
                "inertia)"
            ),
            False,
        )
    if shape.shape == "falls":
        return (
            "unstable",
            head
            + (
                "; along the path the potential falls beside the point"
                f"{_power_words(shape.order)}, so released there at rest the body runs away, and "
                "cannot come back past the higher potential: unstable"
            ),
            True,
        )
    what = (
        "no force acts beside the point either"
        if shape.shape == "level"
        else "the higher-order test cannot tell the potential's shape here"
    )
    return "marginal", head + f"; {what}: the coordinate is singular here, so no verdict", False
