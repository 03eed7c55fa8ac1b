"""The conserved-quantities step with forces that do no work: dE/dt = Σ_j Q_j q̇_j (notes eq. 23).

A Lorentz force q v × B acts (Q ≠ 0) but its power Σ_j Q_j q̇_j is 0, so E = T + V is
conserved; the step must list it and must not say the forces do work. Expectations by hand: the
power of each force written out, E = T + V of a trapped particle, and E along an independent
scipy integration of the same equations.
"""

from __future__ import annotations

import numpy as np
import scipy.integrate
import sympy as sp

from mechanics.derive import derive_model
from mechanics.expr import to_plain

M_, K_, Q_, B_ = 1.0, 1.0, 1.0, 0.5


def charge(force: list, position: list | None = None, coordinates=("x", "y")) -> dict:
    """A charge in the trap V = k (x² + y²)/2 (or k r²/2), with one force on it."""
    trap = "k*(x**2 + y**2)/2" if coordinates == ("x", "y") else "k*r**2/2"
    return {
        "title": "Charge in a magnetic field",
        "coordinates": list(coordinates),
        "parameters": {"m": M_, "k": K_, "q": Q_, "B": B_, "c": 0.2},
        "bodies": [{"name": "p", "mass": "m", "position": position or ["x", "y", 0]}],
        "potentials": [{"name": "trap", "expression": trap}],
        "forces": [{"name": "f", "on": "p", "vector": force}],
    }


def conserved(spec: dict) -> tuple[dict, str]:
    d = derive_model(spec)
    step = next(s for s in d.steps if s.id == "conserved")
    return {c["name"]: c["expr"] for c in d.work.conserved}, step.text


def test_the_lorentz_force_does_no_work_so_energy_is_conserved():
    """Q_x ẋ + Q_y ẏ = q B ẏ ẋ − q B ẋ ẏ = 0: E = m(ẋ² + ẏ²)/2 + k(x² + y²)/2 is conserved, and
    scipy's integration of m ẍ = −k x + q B ẏ, m ÿ = −k y − q B ẋ keeps it to 1e-9."""
    found, text = conserved(charge(["q*B*y_dot", "-q*B*x_dot", 0]))
    assert "energy" in found, text
    x, y, xd, yd, m, k = sp.symbols("x y x_dot y_dot m k")
    by_hand = m * (xd**2 + yd**2) / 2 + k * (x**2 + y**2) / 2
    assert sp.simplify(sp.sympify(to_plain(found["energy"])) - by_hand) == 0
    assert "do no work" in text and "changes by" not in text

    def rhs(t, s):
        x, y, vx, vy = s
        return [vx, vy, (-K_ * x + Q_ * B_ * vy) / M_, (-K_ * y - Q_ * B_ * vx) / M_]

    sol = scipy.integrate.solve_ivp(rhs, (0, 30), [0.1, 0, 0, 0.2], rtol=1e-12, atol=1e-14)
    E = M_ * (sol.y[2] ** 2 + sol.y[3] ** 2) / 2 + K_ * (sol.y[0] ** 2 + sol.y[1] ** 2) / 2
    assert np.ptp(E) <= 1e-9 * E[0]

    # power −c ẋ² or c ẋ⁴: not 0, so E changes by W^NC and stays off the list (as before)
    for drag in ("-c*x_dot", "c*x_dot**3"):
        found, text = conserved(charge([drag, 0, 0]))
        assert "energy" not in found and "do work" in text, drag


def test_the_lorentz_force_in_polar_coordinates_does_no_work_after_trig_identities():
    """In (r, θ): Q_r = q B r θ̇ and Q_θ = −q B r ṙ once sin² + cos² = 1, so the power
    q B r θ̇ ṙ − q B r ṙ θ̇ is 0 again; a drag −c v beside it does work (−c v² ≤ 0): no E."""
    vx, vy = "r_dot*cos(th) - r*th_dot*sin(th)", "r_dot*sin(th) + r*th_dot*cos(th)"
    polar = ["r*cos(th)", "r*sin(th)", 0]
    found, text = conserved(
        charge([f"q*B*({vy})", f"-q*B*({vx})", 0], polar, coordinates=("r", "th"))
    )
    assert "energy" in found and "do no work" in text, text
    found, text = conserved(
        charge([f"q*B*({vy}) - c*({vx})", f"-q*B*({vx}) - c*({vy})", 0], polar, ("r", "th"))
    )
    assert "energy" not in found and "do work" in text, text
