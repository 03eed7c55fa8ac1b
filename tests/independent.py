"""The independent integration tests compare the engine with: scipy's DOP853 on equations the
test wrote by hand, far tighter than any run under test."""

from __future__ import annotations

from scipy.integrate import solve_ivp


def own_run(rhs, y0, t_eval, events=None):
    sol = solve_ivp(
        rhs,
        (0.0, float(t_eval[-1])),
        y0,
        method="DOP853",
        t_eval=t_eval,
        rtol=1e-12,
        atol=1e-13,
        events=events,
    )
    assert sol.success, sol.message
    return sol
