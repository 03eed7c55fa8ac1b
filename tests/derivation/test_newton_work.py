"""Newton's method gives Lagrange's equations; constraint forces and the work-energy principle."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app
from mechanics.derive import derivation_of_scene
from mechanics.expr import parse
from mechanics.newton import newton
from mechanics.scenes import scene_ids

client = TestClient(app)


@pytest.mark.parametrize("scene_id", scene_ids())
def test_newton_gives_the_same_equations_as_lagrange(scene_id):
    """Σ_i (m a_i − F_i)·∂r_i/∂q_j (+ rigid bodies' dH/dt) against d/dt ∂L/∂q̇ − ∂L/∂q − Q."""
    d = derivation_of_scene(scene_id)
    _, _, residual = newton(d)
    m = d.model
    rng = np.random.default_rng(1)
    for _ in range(20):
        state = {s: sp.Float(rng.uniform(0.2, 1.2)) for s in [*m.q, *m.qd, *m.qdd]}
        state.update(
            {
                p: sp.Float(v or 0.5)
                for p, v in zip(m.params.values(), m.spec.parameters.values(), strict=True)
            }
        )
        state[m.names["t"]] = sp.Float(0.7)
        for r, lhs, Q in zip(residual, d.work.eom_lhs, d.work.Q, strict=True):
            ours, theirs = (float(e.xreplace(state)) for e in (r, lhs - Q))
            assert ours == pytest.approx(theirs, rel=1e-10, abs=1e-10)


def test_pendulum_tension_is_m_g_cos_theta_plus_m_l_theta_dot_squared():
    d = derivation_of_scene("simple_pendulum")
    _, forces, _ = newton(d)
    (bob,) = forces
    m, g, length = (d.model.params[k] for k in ("m", "g", "l"))
    theta, theta_dot = d.model.q[0], d.model.qd[0]
    assert bob.support[0] == "O"
    assert sp.simplify(bob.support[1] - m * (g * sp.cos(theta) + length * theta_dot**2)) == 0


def test_pendulum_balance_is_written_in_polar_components_as_the_notes_do():
    steps, _, _ = newton(derivation_of_scene("simple_pendulum"))
    plain = steps[0].to_json()["plain"]
    assert "m a_theta = l*m*theta_ddot = -g*m*sin(theta)" in plain
    assert "m a_r = -l*m*theta_dot**2 = g*m*cos(theta) - F_T_bob" in plain


def test_atwood_string_tension():
    r = client.post("/api/v1/newton", json={"scene_id": "atwood_machine"}).json()
    assert r["agrees_with_lagrange"]
    m1, m2, g = 2.0, 1.0, 9.81  # the scene's defaults
    expected = 2 * m1 * m2 * g / (m1 + m2)
    for f in r["constraint_forces"]:
        y = f["components"][1]
        names = {k: sp.Symbol(k) for k in ("m1", "m2", "g")}
        value = parse(y, names).subs({names["m1"]: m1, names["m2"]: m2, names["g"]: g})
        assert float(value) == pytest.approx(expected)


def test_tension_along_a_simulated_swing_and_slack_warning():
    body = {
        "scene_id": "simple_pendulum",
        "t_end": 2,
        "fps": 50,
        "constraint_forces": True,
        "rtol": 1e-10,
        "atol": 1e-10,
    }
    r = client.post("/api/v1/simulate", json=body).json()
    m, g, length = 1.0, 9.81, 1.0
    theta, theta_dot = np.array(r["q"]["theta"]), np.array(r["q_dot"]["theta"])
    tension = np.array(r["constraint_forces"]["bob"]["tension"])
    assert np.allclose(tension, m * (g * np.cos(theta) + length * theta_dot**2), rtol=1e-9)
    slack = client.post("/api/v1/simulate", json={**body, "initial": {"theta": 2.5}}).json()
    assert any("slack" in w for w in slack["warnings"])


@pytest.mark.parametrize(
    ("scene_id", "forces"),
    [
        ("spring_mass_damper", {"damper:damper@block", "force:drive"}),
        ("incline_friction", {"force:friction"}),
    ],
)
def test_work_energy_principle_between_two_times(scene_id, forces):
    """W^NC_1→2 = ΔT + ΔV (notes eq. 23), each force's work from its own power."""
    r = client.post(
        "/api/v1/simulate",
        json={"scene_id": scene_id, "t_end": 4, "fps": 100, "rtol": 1e-11, "atol": 1e-11},
    ).json()
    i, j = 37, 311
    work = r["work"]
    assert set(work["non_conservative"]) == forces
    e = r["energy"]
    dT, dV = e["T"][j] - e["T"][i], e["V"][j] - e["V"][i]
    w_nc = sum(w[j] - w[i] for w in work["non_conservative"].values())
    assert w_nc == pytest.approx(dT + dV, rel=1e-6)
    assert e["W_nc"][j] - e["W_nc"][i] == pytest.approx(dT + dV, rel=1e-8)
    w_c = sum(w[j] - w[i] for w in work["conservative"].values())
    assert w_c == pytest.approx(-dV, rel=1e-12, abs=1e-12)


def test_conservative_scene_has_no_non_conservative_work():
    r = client.post(
        "/api/v1/simulate",
        json={"scene_id": "double_pendulum", "t_end": 3, "rtol": 1e-12, "atol": 1e-12},
    ).json()
    assert r["work"]["non_conservative"] == {}
    E = np.array(r["energy"]["E"])
    assert np.max(np.abs(E - E[0])) < 1e-8 * np.max(np.abs(r["energy"]["T"]))
