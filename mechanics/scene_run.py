"""One integration of a compiled scene with the method asked for, or the one that must run instead.

Why a module of its own: which method actually runs is a decision with reasons (a scene whose
stops chatter is stepped in Python, watched every step; a scene whose equations C cannot print is
called back from the C loop; a server without a C compiler runs scipy's DOP853), and the answer's
``stats.method`` must name the method that ran, not the one asked for. `run_scene` makes the
decision, runs it, and leaves the reason in ``Trajectory.note`` and the method in
``Trajectory.method``.
"""

from __future__ import annotations

import numpy as np

from mechanics.integrators import Trajectory, integrate
from mechanics.native import NativeUnavailable
from mechanics.numeric import CompiledScene
from mechanics.stops import watch_for_stops

#: The method /simulate runs when none is named: DOP853's steps, taken in C (the same steps as
#: scipy's DOP853, a few ms a run instead of 50-200 ms, with the GIL released while it steps).
DEFAULT_METHOD = "dop853_c"


def run_scene(
    c: CompiledScene,
    params: list[float],
    y0: np.ndarray,
    t_eval: np.ndarray,
    *,
    method: str,
    dt: float | None,
    rtol: float,
    atol: float,
    max_wall_time: float,
) -> Trajectory:
    """One integration; a scene with stops gets a fresh `StopWatch` (``run.watch``).

    The C loop is not watched: its samples are searched afterwards, which finds every smooth
    stop. A stop where the motion reverses (friction sticking) makes the steps chatter at a
    discontinuity instead of crossing it, so such scenes step in Python, watched every step.
    """
    compiled, why = None, ""
    watch = watch_for_stops(c, params, y0)
    # a spring through its anchor crosses smoothly (found on the samples); friction chatters
    chatter = any(stop.crossing == "any" and stop.kind != "anchor" for stop in c.stops)
    domain = any(stop.kind == "domain" for stop in c.stops)
    if method == "dop853_c" and (chatter or domain):
        method = "DOP853"
        why = "stepped by scipy's DOP853 (the same steps) so " + (
            "a reversal is caught every step"
            if chatter
            else "the end of a position's domain, approached tangentially, is caught every step"
        )
    elif method == "dop853_c":
        try:
            compiled = c.native_rhs(params)
        except NativeUnavailable as exc:  # the C loop calls the Python right-hand side back
            why = f"The equations could not be compiled to C ({exc}): the C loop called Python."
    run = integrate(
        c.rhs(params),
        y0,
        t_eval,
        method=method,
        rtol=rtol,
        atol=atol,
        dt=dt,
        max_wall_time=max_wall_time,
        second_order=c.n,
        native=compiled,
        watch=watch,
    )
    if why and not run.note:
        run.note = why[0].upper() + why[1:] if why.endswith(".") else f"This scene was {why}."
    run.watch = watch
    return run
