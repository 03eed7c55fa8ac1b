"""What the independent tests compare the engine with: scipy's DOP853 on equations the test
wrote by hand, far tighter than any run under test; numpy's eigenvalues of a linearization
the test derived by hand."""

from __future__ import annotations

import numpy as np
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


def first_order_eigenvalues(M, C, K) -> np.ndarray:
    """λ of M x'' + C x' + K x = 0, from the first-order form, sorted for comparison."""
    M, C, K = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (M, C, K))
    n = len(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.sort_complex(np.round(np.linalg.eigvals(A), 9))


def engine_eigenvalues(e: dict) -> np.ndarray:
    """An equilibrium's eigenvalues as the engine reports them, sorted the same way."""
    return np.sort_complex(np.round(np.array([complex(a, b) for a, b in e["eigenvalues"]]), 9))
