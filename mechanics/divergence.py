"""How two runs of the same motion part: exponentially (chaos) or steadily (a timing drift).

The simulation checks itself by re-running at a looser tolerance and comparing. A difference
alone says little: in a regular (integrable) motion the two runs have slightly different
periods, so they drift apart in phase — the difference grows like t (or t² when the energy
error drifts too) while the shape of the motion stays right. In a chaotic motion any small
error is amplified like e^{λ t} (λ: the largest Lyapunov exponent), and after a while the run
says nothing about the detail of the true motion.

`classify_divergence` tells the two apart from the data, the way one would by eye on a plot of
log d against t. Over the stretch where d is above numerical noise and below saturation (d
cannot grow beyond the size of the motion) it fits a plateau plus e^{λ t} (log d against t a
straight line) and a plateau plus t^p (log d against log t a straight line), robustly, and keeps
the better model when it is better by a clear margin and physically plausible; otherwise it says
so. Physics gives a strong prior: an autonomous motion with one degree of freedom (after the
cyclic coordinates, whose momenta are conserved, drop out) has a two-dimensional phase space,
where trajectories cannot cross, so it cannot be chaotic (Poincaré–Bendixson).

Only the words differ by kind. Chaos: trust the details up to where the runs part. A drift:
the timing is off, the shape is right, and the looser run carries most of the difference.

>>> t = np.linspace(0.0, 20.0, 1201)
>>> d = np.minimum(1e-9 * np.exp(1.3 * t), 1.0)  # e^{1.3 t}, saturating at the motion's size
>>> v = classify_divergence(t, d, span=1.0, n_dof=2, autonomous=True)
>>> v.kind, round(v.rate, 2)
('exponential', 1.3)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import median_filter
from scipy.optimize import least_squares

from mechanics.numeric import CompiledScene

#: Relative differences (of the span) below this are numerical noise, whatever the run.
NOISE = 1e-13
#: Above this relative difference the growth saturates (a phase drift by ~0.1 rad, chaos at the
#: size of the motion): the fits stop there.
SATURATION = 0.1
#: The fits use at most this many decades of d below where they stop (the earliest part of
#: the run is the errors being injected, not yet their growth).
FIT_DECADES = 4.0
#: Noise is the level the difference reaches in this first fraction of the fitted stretch.
EARLY = 0.1
#: A model is plausible if it explains this much of log d's variance (R² ≥ 0.8).
FIT_QUALITY = 0.2
#: The winning model's mean squared residual of log d must be this many times smaller.
MARGIN = 2.0
#: A power law steeper than this is not a drift one can read off a timing error.
MAX_POWER = 4.0
#: A growth slower than t^MIN_POWER over the run is no systematic growth.
MIN_POWER = 0.3
#: The fits use at most this many samples (evenly spread), so a long run costs the same.
MAX_FIT_POINTS = 800
#: Relative difference at which the detail of a chaotic run ends ("trust it up to t").
TRUST = 1e-2
#: A drift (or an unclear difference) is reported once it reaches this fraction of the span
#: (a phase error of about 0.05 rad); smaller ones are the ordinary cost of a tolerance, and
#: without exponential growth most of the difference is the looser run's own error.
DRIFT_WARNING = 5e-2
#: Up to this the runs are out of step by a small part of a period (phase error ≲ 0.5 rad).
SMALL_PHASE = 0.5
#: A drift is "mostly timing" when a time shift removes all but this fraction of it.
TIMING_ONLY = 0.3
#: The largest time shift searched (s).
MAX_SHIFT = 5.0
#: Beyond this the runs differ by more than a phase drift of bounded motion can (2 × span).
QUALITATIVE = 2.5


@dataclass(frozen=True)
class Divergence:
    """What the comparison of two runs shows, and the sentence a student reads ("" if none)."""

    kind: str  # "exponential" | "polynomial" | "none" | "unclear"
    rate: float | None = None  # exponential: λ (1/s); polynomial: drift of d/span per second
    power: float | None = None  # polynomial: p in d ∝ t^p
    doubling_time: float | None = None  # exponential: ln 2 / λ (s)
    trusted_until: float | None = None  # exponential, unclear: where the runs differ by TRUST
    timing_error: float | None = None  # polynomial, mostly timing: the shift at the end (s)
    message: str = ""


@dataclass(frozen=True)
class TimeShift:
    """The other run slid in time to best match this one over the last stretch of the run."""

    shift: float  # s: the other run matches this one at t + shift (> 0: it lags)
    left: float  # max |Δq| after the shift over max |Δq| before it: 0 pure timing, 1 none


def best_time_shift(t: np.ndarray, q: np.ndarray, q_other: np.ndarray) -> TimeShift:
    """Slide q_other along t to match q over the end of the run.

    A phase drift is undone by a shift (the same motion, later or earlier); a difference in
    shape (amplitude, another kind of motion) is not. Where q oscillates, the match covers its
    last two periods and the shift stays within half a period (a period later matches too);
    otherwise the last tenth of the run and shifts up to a quarter of it, at most MAX_SHIFT s.
    """
    t, q, q_other = (np.asarray(a, dtype=float) for a in (t, q, q_other))
    if len(t) < 4:
        return TimeShift(0.0, 0.0)
    duration = t[-1] - t[0]
    middle = 0.5 * (np.max(q) + np.min(q))
    crossings = t[np.nonzero(np.diff(np.sign(q - middle)) != 0)[0]]
    if len(crossings) >= 3:
        period = 2.0 * float(np.median(np.diff(crossings)))
        stretch, reach = min(max(0.1 * duration, 2 * period), 0.5 * duration), 0.5 * period
    else:
        stretch, reach = 0.1 * duration, 0.25 * duration
    reach = min(reach, MAX_SHIFT, 0.25 * duration)
    last = np.nonzero((t >= t[-1] - stretch - reach) & (t <= t[-1] - reach))[0]
    last = last[:: max(1, len(last) // MAX_FIT_POINTS)]
    if not len(last):  # a run of a few samples: no stretch before the shift's reach to match
        return TimeShift(0.0, 0.0)
    before = float(np.max(np.abs(q[last] - q_other[last])))
    if before == 0.0:
        return TimeShift(0.0, 0.0)
    step = 0.5 * float(np.min(np.diff(t)))
    shifts = np.arange(-reach, reach + step / 2, step)
    # every shift at once: one interpolation of len(shifts) × len(last) points
    slid = np.interp((t[last][None, :] + shifts[:, None]).ravel(), t, q_other)
    errors = np.max(np.abs(q[last][None, :] - slid.reshape(len(shifts), len(last))), axis=1)
    best = int(np.argmin(errors))
    return TimeShift(float(shifts[best]), float(errors[best]) / before)


@dataclass(frozen=True)
class _Fit:
    """log d = log(d0 + A g(t)) with g = e^{λ t} or t^p: growth on top of a noise plateau d0."""

    slope: float  # λ (1/s) or p
    intercept: float  # log A
    offset: float  # log d0
    residual: float  # mean squared residual of log d

    def at(self, x: float) -> float:
        """The growing part A g(t) alone, at x = t (exponential) or log t (power law)."""
        return math.exp(self.intercept + self.slope * x)


def chaos_possible(n_dof: int, autonomous: bool) -> bool:
    """An autonomous flow needs three phase-space dimensions for chaos: two degrees of freedom.

    ``n_dof`` counts the coordinates left after the cyclic ones (each has a conserved momentum
    and drops out, Routh): a spherical pendulum or a central force has one.
    """
    return n_dof >= 2 or not autonomous


def is_autonomous(
    rhs: Callable[[float, np.ndarray], np.ndarray], t: np.ndarray, y: np.ndarray
) -> bool:
    """Does dy/dt = rhs(t, y) not depend on t explicitly? Checked on states of the run itself.

    Numeric on purpose: it reads the compiled equations, not the derivation, and it is exact
    where t cancels (a hoop spun at constant Ω has a time-free equation in the hoop's frame).
    """
    if len(t) == 0:
        return True
    for i in np.unique(np.linspace(0, len(t) - 1, 5).astype(int)):
        state = np.asarray(y[i], dtype=float)
        here = np.asarray(rhs(float(t[i]), state), dtype=float)
        for shift in (0.7310585786, 3.1415926536, 17.320508076):
            there = np.asarray(rhs(float(t[i]) + shift, state), dtype=float)
            if not np.allclose(here, there, rtol=1e-9, atol=1e-12 * (1 + np.max(np.abs(here)))):
                return False
    return True


#: Below this largest relative difference no sentence is said whatever the growth: a chaotic
#: run is trusted until the runs part by TRUST, a drift is told from DRIFT_WARNING.
SILENT_BELOW = min(TRUST, DRIFT_WARNING)


def worth_classifying(n: int, y: np.ndarray, y_other: np.ndarray) -> bool:
    """Could `compare_runs` say anything about these runs? Only if some coordinate parts by
    SILENT_BELOW of its span (the envelope it classifies never exceeds the raw difference).
    Every page run of the catalog parts by under 1e-3: the two robust fits (8 of a page run's
    10 ms of CPU) would only confirm that there is nothing to say."""
    span = np.max(np.abs(y[:, :n]), axis=0) + 1e-12
    with np.errstate(invalid="ignore"):
        largest = np.max(np.abs(y_other[:, :n] - y[:, :n]) / span, initial=0.0)
    return not largest < SILENT_BELOW  # a NaN (an overflowing run) is worth a look too


def compare_runs(
    c: CompiledScene,
    params: list[float],
    t: np.ndarray,
    y: np.ndarray,
    y_other: np.ndarray,
    tolerances: tuple[float, float],
) -> Divergence:
    """Classify how a run (states y at times t) and a re-run (y_other) of scene c part.

    The coordinate that parts most (relative to its span, max |q|) speaks for the motion; the
    scene supplies the prior (degrees of freedom less cyclic ones, explicit time or not); the
    best time shift between the runs says how much of a drift is timing.
    """
    n = c.n
    diff = np.abs(y_other[:, :n] - y[:, :n])
    span = np.max(np.abs(y[:, :n]), axis=0) + 1e-12
    worst = int(np.argmax(np.max(diff / span, axis=0)))
    return classify_divergence(
        t,
        diff[:, worst],
        float(span[worst]),
        n_dof=n - len(c.momenta),
        autonomous=is_autonomous(c.rhs(params), t, y),
        cyclic=tuple(c.momenta),
        name=c.coordinates[worst],
        tolerances=tolerances,
        time_shift=best_time_shift(t, y[:, worst], y_other[:, worst]),
    )


def _fit(x: np.ndarray, y: np.ndarray) -> _Fit:
    """Fit y = log(e^c + e^{a + k x}), k ≥ 0, robustly (soft L1: a few odd samples do not rule).

    With x = t this is a plateau plus e^{λ t}; with x = log t a plateau plus t^p. The plateau
    is the error the first steps inject, which neither growth law describes.
    """
    k0, a0 = np.polyfit(x, y, 1)
    lo, hi = float(np.min(y)), float(np.max(y))
    start = [lo - 1.0, float(a0), float(np.clip(k0, 1e-6, 1e3))]

    def residuals(params: np.ndarray) -> np.ndarray:
        c, a, k = params
        return np.logaddexp(c, a + k * x) - y

    def jacobian(params: np.ndarray) -> np.ndarray:
        """Exact, so the fit costs one evaluation a step instead of four (finite differences)."""
        c, a, k = params
        plateau = np.exp(c - np.logaddexp(c, a + k * x))  # ∂/∂c; the growth's share is the rest
        return np.column_stack([plateau, 1.0 - plateau, (1.0 - plateau) * x])

    solution = least_squares(
        residuals,
        start,
        jac=jacobian,
        bounds=([lo - 30.0, -np.inf, 0.0], [hi, np.inf, 1e4]),
        loss="soft_l1",
        f_scale=0.5,
    )
    c, a, k = solution.x
    residual = float(np.mean(residuals(solution.x) ** 2))
    return _Fit(float(k), float(a), float(c), residual)


def _window(t: np.ndarray, envelope: np.ndarray, stop: int) -> np.ndarray:
    """Indices where the growth shows: above the noise, before saturation (index `stop`).

    Noise is what the first steps inject before any growth: the larger of the level reached
    in the first tenth of the stretch and FIT_DECADES below the top.
    """
    early = int(np.searchsorted(t, EARLY * t[stop]))
    floor = max(NOISE, float(envelope[stop]) * 10.0**-FIT_DECADES, float(envelope[early]))
    window = np.nonzero((envelope >= floor) & (t > 0))[0]
    return window[window <= stop]


def _verdict(
    exponential: _Fit, power: _Fit, times: np.ndarray, logs: np.ndarray
) -> tuple[str, bool]:
    """The better model by MARGIN among the plausible ones.

    Exponential is plausible with λ > 0 over at least two decades of growth (chaos amplifies
    a tolerance-sized error by many decades; a factor of ten says little); a power law with
    MIN_POWER ≤ p ≤ MAX_POWER (a steeper one over a short stretch is an exponential seen
    through the wrong glasses: no timing drift grows like t^10). Also says whether the power
    law was plausible, so that a sentence may quote its exponent.
    """
    grown = logs[-1] - logs[0]
    if power.slope < MIN_POWER and exponential.slope * (times[-1] - times[0]) < math.log(3.0):
        return "none", False
    spread = float(np.var(logs))
    plausible_exp = (
        exponential.slope * (times[-1] - times[0]) >= math.log(100.0)
        and grown >= math.log(100.0)
        and exponential.residual <= FIT_QUALITY * spread
    )
    plausible_pow = MIN_POWER <= power.slope <= MAX_POWER and power.residual <= FIT_QUALITY * spread
    if plausible_exp and (not plausible_pow or exponential.residual * MARGIN < power.residual):
        return "exponential", plausible_pow
    if plausible_pow and (not plausible_exp or power.residual * MARGIN < exponential.residual):
        return "polynomial", plausible_pow
    return "unclear", plausible_pow


def _tol(tolerances: tuple[float, float] | None) -> str:
    return f" at rtol {tolerances[0]:g} and {tolerances[1]:g}" if tolerances else ""


def _percent(x: float) -> str:
    return f"{100 * x:.0f} %" if x >= 0.1 else f"{100 * x:.2g} %"


def _whose(tolerances: tuple[float, float] | None) -> str:
    """Without exponential growth the looser run carries most of the difference: which is it?"""
    if not tolerances or tolerances[0] == tolerances[1]:
        return ""
    return "the looser run's" if tolerances[0] < tolerances[1] else "this run's"


def classify_divergence(
    t: np.ndarray,
    diff: np.ndarray,
    span: float,
    n_dof: int,
    autonomous: bool,
    *,
    name: str = "the coordinate",
    tolerances: tuple[float, float] | None = None,
    time_shift: TimeShift | None = None,
    cyclic: tuple[str, ...] = (),
) -> Divergence:
    """Classify how |diff| (two runs' difference in one coordinate) grows along the run.

    ``span`` is the size of that coordinate's motion (the differences are taken relative to
    it), ``n_dof`` the degrees of freedom left after cyclic coordinates, ``autonomous`` whether
    the equations are free of explicit t. ``tolerances`` (this run's rtol, the looser one) and
    ``time_shift`` (`best_time_shift` of the two runs) only enrich the message: with a time
    shift a drift is told as timing only where a shift undoes it. ``cyclic`` names the cyclic
    coordinates n_dof left out, so the sentence counts the coordinates as the scene has them.
    """
    t = np.asarray(t, dtype=float)
    d = np.abs(np.asarray(diff, dtype=float)) / max(float(span), 1e-300)
    if len(t) != len(d):
        raise ValueError("t and diff must have the same length")
    if len(t) < 2 or not np.all(np.isfinite(d)):
        return Divergence("unclear")
    # The running maximum, so that zero crossings of d do not count; of a running median, so
    # that a lone outlier (one sample of a coarse step's interpolation) does not either.
    envelope = np.maximum.accumulate(median_filter(d, size=5, mode="nearest"))
    largest = float(envelope[-1])
    crossed = np.nonzero(envelope >= TRUST)[0]
    parted = float(t[crossed[0]]) if len(crossed) else None
    if largest <= NOISE:
        return Divergence("none")
    stop = int(np.argmax(envelope >= SATURATION)) if largest >= SATURATION else len(t) - 1
    window = _window(t, envelope, stop)
    if len(window) < 8 or envelope[stop] < 3 * envelope[window[0]]:
        kind = "none"
        return Divergence(kind, message=_neutral(largest, parted, name, tolerances, kind))
    window = window[:: max(1, len(window) // MAX_FIT_POINTS)]
    times, logs = t[window], np.log(envelope[window])
    exponential = _fit(times, logs)
    power = _fit(np.log(times), logs)
    kind, power_law = _verdict(exponential, power, times, logs)
    forced = False
    if kind in ("exponential", "unclear") and not chaos_possible(n_dof, autonomous):
        # Chaos is impossible here, so a growing difference is a drift in phase (and energy),
        # however it looks over a short stretch: near a separatrix the period depends steeply
        # on the energy, and a loose run's energy error may itself grow.
        kind, forced = "polynomial", True
    if kind == "exponential":
        rate = exponential.slope
        return Divergence(
            kind,
            rate=rate,
            doubling_time=math.log(2.0) / rate,
            trusted_until=parted,
            message=_chaotic(rate, parted, name, tolerances),
        )
    if kind == "polynomial":
        timing = time_shift if time_shift and time_shift.left <= TIMING_ONLY else None
        drift = Drift(
            power.slope if power_law else None,
            largest,
            float(t[-1]),
            timing,
            checked=time_shift is not None,
            forced=forced,
            cyclic=cyclic,
            n_dof=n_dof,
        )
        return Divergence(
            kind,
            rate=float(envelope[stop] / t[stop]),
            power=power.slope if power_law else None,
            timing_error=abs(timing.shift) if timing else None,
            message=_drift(drift, name, tolerances),
        )
    return Divergence(
        kind, trusted_until=parted, message=_neutral(largest, parted, name, tolerances, kind)
    )


def _chaotic(rate: float, parted: float | None, name: str, tolerances) -> str:
    if parted is None:
        return ""  # still within 1 % at the end: the run is good as it stands
    more = ""
    if tolerances:
        factor = tolerances[1] / tolerances[0]
        more = (
            f" A {factor:g}× tighter rtol buys only about ln({factor:g})/λ ≈ "
            f"{math.log(factor) / rate:.2g} s more."
        )
    return (
        f"The motion is sensitive to small errors (chaotic): the runs{_tol(tolerances)} part "
        f"exponentially — the difference in {name} grows like e^(λt) with λ ≈ {rate:.2g} /s, "
        f"doubling every {math.log(2.0) / rate:.2g} s. They differ by 1 % of its span from "
        f"t ≈ {parted:.3g} s: trust the details up to about there; the energy and the overall "
        f"character of the motion stay meaningful after.{more}"
    )


@dataclass(frozen=True)
class Drift:
    """What the sentence about a drift needs."""

    power: float | None  # p in d ∝ t^p, when the power law fits
    largest: float  # the largest difference, relative to the span
    t_end: float
    timing: TimeShift | None  # when a time shift undoes most of the difference
    checked: bool  # whether a time shift was tried at all
    forced: bool  # classified by the prior (chaos impossible), not by the fit
    cyclic: tuple[str, ...] = ()  # cyclic coordinates set aside (their momenta conserved)
    n_dof: int = 1  # the coordinates left


def _phase_plane(drift: Drift) -> str:
    """Why chaos is impossible, counting the coordinates as the scene has them: the spherical
    pendulum has two, θ and the cyclic φ, and was told it had "one coordinate"."""
    if not drift.cyclic:
        return "there is one coordinate and no explicit time (a phase plane)"
    names = ", ".join(drift.cyclic)
    verb = "is" if len(drift.cyclic) == 1 else "are"
    its = "its momentum" if len(drift.cyclic) == 1 else "their momenta"
    if drift.n_dof < 1:
        return f"{names} {verb} cyclic ({its} conserved) and there is no explicit time"
    return (
        f"{names} {verb} cyclic ({its} conserved), which leaves one coordinate and no "
        "explicit time (a phase plane)"
    )


def _drift(drift: Drift, name: str, tolerances) -> str:
    if drift.largest < DRIFT_WARNING:
        return ""
    if drift.largest >= QUALITATIVE:
        return (
            f"The runs{_tol(tolerances)} part, though not exponentially: by t = "
            f"{drift.t_end:.3g} s they differ in {name} by {_percent(drift.largest)} of its "
            "span, more than the size of the motion itself, so the looser run moves "
            "differently (e.g. over the top instead of back). Tighten rtol and compare again."
        )
    p = drift.power
    growth = "" if p is None else " linearly" if 0.7 <= p <= 1.3 else f" like t^{p:.1f}"
    if drift.forced:
        text = (
            f"The runs{_tol(tolerances)} drift apart in phase: {_phase_plane(drift)}, so "
            "errors cannot keep growing exponentially (they may grow fast for a while, near "
            "the top of a swing, but not for good)."
        )
    else:
        text = f"The runs{_tol(tolerances)} drift apart steadily in phase, not exponentially."
    text += (
        f" The difference in {name} grows{growth}, to {_percent(drift.largest)} of its span by "
        f"t = {drift.t_end:.3g} s"
    )
    whose = _whose(tolerances)
    if not drift.checked:
        text += f", most of it {whose}." if whose else "."
        return text + " Tighten rtol if exact timing matters."
    if drift.timing is None:
        return text + (
            ". A time shift does not undo it: the runs differ in amplitude (energy) as well as "
            "timing. Tighten rtol if the details matter."
        )
    if drift.largest > SMALL_PHASE:
        text += ": by the end they are out of step by a large part of a period"
    else:
        lead = "behind" if drift.timing.shift > 0 else "ahead of"
        text += (
            f": the looser run is {abs(drift.timing.shift):.2g} s {lead} the tighter "
            f"({abs(drift.timing.shift) / drift.t_end:.1e} of the elapsed time)"
        )
    text += f", most of it {whose}." if whose else "."
    return text + " The shape agrees: tighten rtol if exact timing matters."


def _neutral(largest: float, parted: float | None, name: str, tolerances, kind: str) -> str:
    if largest < DRIFT_WARNING or parted is None:
        return ""
    if kind == "none" and _whose(tolerances) == "the looser run's":
        return ""  # an error the looser run made early and never grew: nothing about this run
    how = (
        "without a steady growth"
        if kind == "none"
        else "growing neither clearly exponentially nor steadily"
    )
    return (
        f"The runs{_tol(tolerances)} differ in {name} by up to {_percent(largest)} of its span "
        f"(1 % from t ≈ {parted:.3g} s), {how}. Compare at a tighter rtol before relying "
        "on the details after that."
    )
