"""The free-body diagram step: constraint forces named and placed as a textbook does, and only
true statements about their virtual work (per body only where provable; notes eq. 18–20)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app
from mechanics.derive import derivation_of_scene, derive_scene
from mechanics.expr import parse
from mechanics.newton import newton

client = TestClient(app)


def fbd_data(scene_id: str) -> dict:
    step = next(s for s in derive_scene(scene_id)["steps"] if s["id"] == "fbd")
    return step["data"]


def placed(scene_id: str) -> dict[str, list[dict]]:
    return {b["body"]: b["constraint_forces"] for b in fbd_data(scene_id)["bodies"]}


def run(scene_id: str, **extra) -> dict:
    body = {"scene_id": scene_id, "t_end": 2, "fps": 50, "rtol": 1e-11, "atol": 1e-11}
    body |= {"constraint_forces": True, **extra}
    r = client.post("/api/v1/simulate", json=body)
    assert r.status_code == 200, r.text
    return r.json()


def xyz(d: dict) -> np.ndarray:
    return np.array([d["x"], d["y"], d["z"]]).T


def test_rolling_disk_has_normal_force_and_static_friction_at_the_contact():
    """By hand: m a = m g sin α + f along the slope, m g cos α = N across it, with
    a = (2/3) g sin α, so f = m a − m g sin α = −(1/3) m g sin α (up the slope)."""
    forces = placed("rolling_disk")["disk"]
    assert [f["name"] for f in forces] == ["F_N", "F_f"]
    m, R, alpha, g = 1.0, 0.3, 0.5, 9.81
    r = run("rolling_disk")
    x = np.array(r["q"]["x"])
    down_slope = np.array([np.cos(alpha), -np.sin(alpha), 0])
    normal = np.array([np.sin(alpha), np.cos(alpha), 0])
    for f in forces:  # at the contact: R below the centre along the surface normal
        assert f["at"] == ["x*cos(alpha)", "-x*sin(alpha)", "0"]
    centre = xyz(r["positions"]["disk"])
    contact = np.stack([x * np.cos(alpha), -x * np.sin(alpha), 0 * x], axis=1)
    assert np.allclose(centre - contact, R * normal, atol=1e-12)
    names = {"alpha": sp.Symbol("alpha")}
    along = {
        f["name"]: np.array(
            [float(parse(c, names).subs(names["alpha"], alpha)) for c in f["along"]]
        )
        for f in forces
    }
    assert np.allclose(along["F_N"], normal) and np.allclose(along["F_f"], down_slope)
    total = xyz(r["constraint_forces"]["disk"])
    assert np.allclose(total @ along["F_f"], -m * g * np.sin(alpha) / 3, rtol=1e-8)
    assert np.allclose(total @ along["F_N"], m * g * np.cos(alpha), rtol=1e-8)
    assert "tension" not in r["constraint_forces"]["disk"]


def test_physical_pendulum_pin_reaction_at_the_pin_by_newton_euler():
    """Rod of length l about its end O, G at l/2: θ̈ = −(3g/2l) sin θ, and m a_G = m g + R gives
    R·ê_r = −m (g cos θ + l θ̇²/2) (a pull toward O), R·ê_θ = m g sin θ / 4."""
    (pin,) = placed("physical_pendulum")["rod"]
    assert pin["name"] == "F_pin" and "pin" in pin["what"]
    assert pin["at"] == ["0", "0", "0"]  # O, not the centre of mass
    m, length, g = 1.0, 1.0, 9.81
    r = run("physical_pendulum")
    assert "tension" not in r["constraint_forces"]["rod"]  # not a rod's tension
    th, thd = np.array(r["q"]["theta"]), np.array(r["q_dot"]["theta"])
    e_r = np.stack([np.sin(th), -np.cos(th), 0 * th], axis=1)
    e_t = np.stack([np.cos(th), np.sin(th), 0 * th], axis=1)
    total = xyz(r["constraint_forces"]["rod"])
    assert np.allclose((total * e_r).sum(1), -m * (g * np.cos(th) + length * thd**2 / 2), rtol=1e-8)
    assert np.allclose((total * e_t).sum(1), m * g * np.sin(th) / 4, rtol=1e-7, atol=1e-9)


def test_bead_on_a_hoop_feels_a_normal_force_not_a_tension():
    (normal,) = placed("bead_on_hoop")["bead"]
    assert normal["name"] == "F_N" and normal["at"] == "bead"
    _, forces, _ = newton(derivation_of_scene("bead_on_hoop"))
    assert forces[0].support is None  # no "tension" toward O
    r = run("bead_on_hoop")
    assert "tension" not in r["constraint_forces"]["bead"]
    assert not any("tension" in w for w in r["warnings"])
    # perpendicular to the hoop (no virtual work), yet with a part across the hoop's plane:
    # the spinning hoop pushes the bead around, so it is not a pull along a radius
    th, R, Om = np.array(r["q"]["theta"]), 0.5, 6.0
    t = np.array(r["t"])
    tangent = np.stack([np.cos(th) * np.cos(Om * t), np.sin(th), -np.cos(th) * np.sin(Om * t)], 1)
    radius = xyz(r["positions"]["bead"]) / R
    total = xyz(r["constraint_forces"]["bead"])
    assert np.allclose((total * tangent).sum(1), 0, atol=1e-9)
    across = total - radius * (total * radius).sum(1)[:, None]
    assert np.max(np.linalg.norm(across, axis=1)) > 1e-3


def test_atwood_masses_are_pulled_by_the_rope_and_no_per_body_claim_is_made():
    forces = placed("atwood_machine")
    assert [f["name"] for f in forces["mass1"]] == ["F_T"] == [f["name"] for f in forces["mass2"]]
    notes = fbd_data("atwood_machine")["constraints"]
    for note in notes:
        assert "does no virtual work" not in note and "summed over all bodies" in note
    # and indeed: F_T does virtual work on mass1 alone, none on the two together
    m1, m2, g = 2.0, 1.0, 9.81
    tension = 2 * m1 * m2 * g / (m1 + m2)
    r = run("atwood_machine", t_end=0.5)
    R1, R2 = xyz(r["constraint_forces"]["mass1"]), xyz(r["constraint_forces"]["mass2"])
    dr1, dr2 = np.array([0, -1, 0]), np.array([0, 1, 0])  # ∂r/∂x of each mass
    assert np.allclose(R1 @ dr1, -tension) and np.allclose(R1 @ dr1 + R2 @ dr2, 0, atol=1e-9)


@pytest.mark.parametrize(
    "scene_id", ["simple_pendulum", "spherical_pendulum", "bead_on_hoop", "incline_friction"]
)
def test_a_per_body_claim_holds_for_that_body(scene_id):
    """Where the step says a body's constraint force does no virtual work, R·∂r/∂q_j = 0."""
    (note,) = fbd_data(scene_id)["constraints"]
    assert "so it does no virtual work" in note
    d = derivation_of_scene(scene_id)
    m = d.model
    _, (force,), _ = newton(d)
    rng = np.random.default_rng(3)
    for q in m.q:
        work = force.vector.dot(m.bodies[0].position.diff(q, m.N))
        for _ in range(5):
            state = {s: rng.uniform(0.2, 1.2) for s in [*m.q, *m.qd]}
            state |= {p: m.spec.parameters[k] for k, p in m.params.items()}
            state[m.names["t"]] = 0.7
            assert abs(float(work.subs(state))) < 1e-9


def test_double_pendulum_inner_rod_pulls_along_itself_once_the_outer_rods_pull_is_taken_off():
    forces = placed("double_pendulum")
    assert [(f["name"], f["part"]) for f in forces["bob1"]] == [("F_T", "pull"), ("F_T", "rest")]
    r = run("double_pendulum")
    p1, p2 = xyz(r["positions"]["bob1"]), xyz(r["positions"]["bob2"])
    R1, R2 = xyz(r["constraint_forces"]["bob1"]), xyz(r["constraint_forces"]["bob2"])
    e2 = (p1 - p2) / np.linalg.norm(p1 - p2, axis=1)[:, None]  # bob2's rod, toward bob1
    T2 = (R2 * e2).sum(1)
    rest = R1 - (-T2[:, None] * e2)  # the outer rod pulls bob1 toward bob2
    e1 = -p1 / np.linalg.norm(p1, axis=1)[:, None]
    assert np.allclose(np.cross(rest, e1)[:, 2], 0, atol=1e-8)
    assert np.allclose(np.cross(R2, e2)[:, 2], 0, atol=1e-8)


def test_step_text_states_the_system_level_principle():
    text = next(s for s in derive_scene("atwood_machine")["steps"] if s["id"] == "fbd")["text"]
    assert "on all bodies together do no virtual work" in text
