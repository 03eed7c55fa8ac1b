"""Where the free-body diagram puts a rigid body's constraint forces: a rolling contact only at a
point of the body that is at rest, never at an instantaneous centre off the body.

The frictionless ladder (rod of length L, foot on the floor, top on the wall, θ from the wall) is
the case that went wrong: its instantaneous centre (L sin θ, L cos θ) is off the rod, and the step
called it a rolling contact with static friction. Every expected value here is worked by hand:
G = (L/2)(sin θ, cos θ), I_G = m L²/12, so T = ½ (m L²/3) θ̇², V = m g (L/2) cos θ and
Lagrange gives θ̈ = (3 g / 2 L) sin θ; the wall end is (0, L cos θ), the floor end (L sin θ, 0).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
import sympy as sp
from fastapi.testclient import TestClient
from specs_beyond import cylinder_in_cylinder, ladder

from app.main import app
from mechanics.derive import derive, derive_model, derive_scene
from mechanics.expr import parse
from mechanics.newton import newton

client = TestClient(app)

LADDER = ladder()

#: A cylinder of radius r rolling inside a fixed cylinder of radius R (the play-test's spec).
CYLINDER = cylinder_in_cylinder()


def fbd(spec: dict) -> dict:
    return next(s for s in derive(spec)["steps"] if s["id"] == "fbd")


def placed(step: dict, body: str) -> list[dict]:
    return next(b for b in step["data"]["bodies"] if b["body"] == body)["constraint_forces"]


def value(plain: str, **numbers: float) -> float:
    names = {k: sp.Symbol(k) for k in numbers}
    return float(parse(plain, names).subs({names[k]: v for k, v in numbers.items()}))


def words(step: dict) -> str:
    forces = [f["what"] for b in step["data"]["bodies"] for f in b["constraint_forces"]]
    return " ".join([step["text"], *step["data"]["constraints"], *forces]).lower()


def with_inertia(**inertia: str) -> dict:
    spec = copy.deepcopy(LADDER)
    spec["bodies"][0]["inertia"] = inertia
    return spec


# ---------------------------------------------------------------------------- the ladder
def test_the_ladder_names_no_friction_and_no_rolling():
    step = fbd(LADDER)
    names = [f["name"] for f in placed(step, "ladder")]
    assert "F_f" not in names
    text = words(step)
    assert (
        "friction" not in text and "roll" not in text and "slip" not in text.replace("slides", "")
    )


def test_the_ladders_forces_act_at_its_ends_on_the_wall_and_the_floor():
    """Each named contact lies on the rod, G + σ ŷ_R with |σ| ≤ L/2 and ŷ_R = (−sin θ, cos θ),
    and the normal there is across the line that end slides along: x̂ at the wall (x = 0), ŷ at the
    floor (y = 0)."""
    forces = placed(fbd(LADDER), "ladder")
    assert sorted(f["name"] for f in forces) == ["F_N", "F_N"]
    assert len({f["label"] for f in forces}) == 2  # one label per force
    L = 2.0
    seen = set()
    for theta in (0.1, 0.5, 0.9, 1.3):
        G = L / 2 * np.array([np.sin(theta), np.cos(theta)])
        axis = np.array([-np.sin(theta), np.cos(theta)])
        for f in forces:
            p = np.array([value(c, theta=theta, L=L) for c in f["at"][:2]])
            sigma = (p - G) @ axis
            assert np.allclose(G + sigma * axis, p, atol=1e-12)  # on the rod's line ...
            assert abs(sigma) <= L / 2 + 1e-12  # ... within the rod
            n = np.array([value(c, theta=theta, L=L) for c in f["along"][:2]])
            if abs(p[0]) < 1e-12:  # the wall end: pushed horizontally
                assert np.allclose(np.abs(n), [1, 0]) and np.isclose(p[1], L * np.cos(theta))
                seen.add("wall")
            else:  # the floor end: pushed vertically
                assert abs(p[1]) < 1e-12 and np.isclose(p[0], L * np.sin(theta))
                assert np.allclose(np.abs(n), [0, 1])
                seen.add("floor")
    assert seen == {"wall", "floor"}


def test_the_ladders_resultant_is_m_a_minus_m_g_and_the_two_normal_forces_turn_it():
    """Along a run: Newton's resultant F_C = m a_G − m g with a_G from θ̈ = (3 g / 2 L) sin θ;
    its components along the FBD's normals are the wall's and the floor's push, and those two,
    at the ends, give the rod's own angular acceleration: (L/2)(N_f sin θ − N_w cos θ) = I_G θ̈
    (ω = θ̇ ẑ, since the frame turns by θ about N.z)."""
    m, L, g = 1.0, 2.0, 9.81
    body = {"scene": LADDER, "t_end": 0.4, "fps": 50, "rtol": 1e-11, "atol": 1e-11}
    r = client.post("/api/v1/simulate", json=body | {"constraint_forces": True})
    assert r.status_code == 200, r.text
    out = r.json()
    theta, w = np.array(out["q"]["theta"]), np.array(out["q_dot"]["theta"])
    alpha = 3 * g / (2 * L) * np.sin(theta)
    ax = L / 2 * (alpha * np.cos(theta) - w**2 * np.sin(theta))
    ay = L / 2 * (-alpha * np.sin(theta) - w**2 * np.cos(theta))
    total = out["constraint_forces"]["ladder"]
    assert np.allclose(total["x"], m * ax, atol=1e-7)
    assert np.allclose(total["y"], m * ay + m * g, atol=1e-7)
    forces = placed(fbd(LADDER), "ladder")
    moment = np.zeros_like(theta)
    for f in forces:  # the FBD's split: F_C projected on each normal, applied at its end
        for i, th in enumerate(theta):
            n = np.array([value(c, theta=th, L=L) for c in f["along"][:2]])
            p = np.array([value(c, theta=th, L=L) for c in f["at"][:2]])
            push = (np.array([total["x"][i], total["y"][i]]) @ n) * n
            arm = p - L / 2 * np.array([np.sin(th), np.cos(th)])
            moment[i] += arm[0] * push[1] - arm[1] * push[0]
    assert np.allclose(moment, m * L**2 / 12 * alpha, atol=1e-7)


def test_newtons_resultant_for_the_ladder_is_the_hand_one_and_sums_the_two_normal_forces():
    d = derive_model(LADDER)
    _, forces, _ = newton(d)
    (F,) = forces
    m, L, g = (d.model.params[k] for k in ("m", "L", "g"))
    th, w = d.model.q[0], d.model.qd[0]
    alpha = 3 * g / (2 * L) * sp.sin(th)
    a = [
        L / 2 * (alpha * sp.cos(th) - w**2 * sp.sin(th)),
        L / 2 * (-alpha * sp.sin(th) - w**2 * sp.cos(th)),
    ]
    N = d.model.N
    expected = [m * a[0], m * a[1] + m * g]
    for got, want in zip((F.vector.dot(N.x), F.vector.dot(N.y)), expected, strict=True):
        assert sp.simplify(got - want) == 0
    assert F.name == "F_C" and len(F.parts) == 2  # F_C = F_N,wall + F_N,floor


# ---------------------------------------------------------------------------- not told: resultant
@pytest.mark.parametrize(
    "inertia",
    [
        # a plank with breadth: no point of it is known to be at the instantaneous centre
        {"ixx": "m*L**2/12", "iyy": "m*L**2/1200", "izz": "m*L**2*101/1200"},
        # a square plate of diagonal L sliding on two corners: round inertia, I_zz = m (L/2)²/3,
        # but the instantaneous centre is a corner's distance from G, off the plate
        {"ixx": "m*L**2/24", "iyy": "m*L**2/24", "izz": "m*L**2/12"},
        # a rod too short to reach the wall and the floor (uniform reach √(3/20) L < L/2)
        {"ixx": "m*L**2/20", "iyy": 0, "izz": "m*L**2/20"},
    ],
)
def test_a_body_whose_contacts_cannot_be_told_gets_only_its_resultant(inertia):
    step = fbd(with_inertia(**inertia))
    assert [f["name"] for f in placed(step, "ladder")] == ["F_C"]
    text = words(step)
    assert "friction" not in text and "roll" not in text
    (note,) = step["data"]["constraints"]
    assert "resultant" in note and "no virtual work" in note


# ---------------------------------------------------------------------------- genuine rolling
def test_the_rolling_disk_keeps_its_rolling_contact_with_friction():
    """The contact is the disk's point on the incline: R from the centre, on the line through O
    along (cos α, −sin α)."""
    step = next(s for s in derive_scene("rolling_disk")["steps"] if s["id"] == "fbd")
    forces = placed(step, "disk")
    assert [f["name"] for f in forces] == ["F_N", "F_f"]
    assert "rolls without slipping" in step["data"]["constraints"][0]
    R, alpha = 0.3, 0.5
    for x in (-0.4, 0.2, 1.1):
        centre = np.array(
            [x * np.cos(alpha) + R * np.sin(alpha), -x * np.sin(alpha) + R * np.cos(alpha)]
        )
        for f in forces:
            p = np.array([value(c, x=x, alpha=alpha) for c in f["at"][:2]])
            assert np.isclose(np.linalg.norm(p - centre), R)
            assert np.isclose(p @ np.array([np.sin(alpha), np.cos(alpha)]), 0, atol=1e-12)


def test_the_cylinder_in_a_cylinder_keeps_its_rolling_contact_on_both_rims():
    step = fbd(CYLINDER)
    forces = placed(step, "cyl")
    assert [f["name"] for f in forces] == ["F_N", "F_f"]
    assert "rolls without slipping" in step["data"]["constraints"][0]
    R, r = 1.0, 0.25
    for theta in (-0.6, 0.2, 1.0):
        G = (R - r) * np.array([np.sin(theta), -np.cos(theta)])
        for f in forces:
            p = np.array([value(c, theta=theta, R=R, r=r) for c in f["at"][:2]])
            assert np.isclose(np.linalg.norm(p - G), r)  # on the small cylinder's rim
            assert np.isclose(np.linalg.norm(p), R)  # on the big one's


def test_a_plank_rocking_on_a_log_rolls_along_itself():
    """A thin plank (mass on its body x axis) rolling without slipping on a fixed log of radius ρ:
    its midpoint is ρ(sin θ − θ cos θ, cos θ + θ sin θ) (an involute) and the contact
    ρ(sin θ, cos θ) is a point of the plank, ρ θ from its middle along it."""
    spec = {
        "title": "plank on a log",
        "coordinates": ["theta"],
        "parameters": {"m": 1.0, "a": 1.0, "rho": 0.5, "g": 9.81},
        "frames": [{"name": "P", "parent": "N", "axis": "z", "angle": "-theta"}],
        "bodies": [
            {
                "name": "plank",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "P",
                "position": [
                    "rho*(sin(theta) - theta*cos(theta))",
                    "rho*(cos(theta) + theta*sin(theta))",
                    0,
                ],
                "inertia": {"ixx": 0, "iyy": "m*a**2/3", "izz": "m*a**2/3"},
            }
        ],
        "gravity": {"acceleration": "g"},
    }
    step = fbd(spec)
    forces = placed(step, "plank")
    assert [f["name"] for f in forces] == ["F_N", "F_f"]
    rho = 0.5
    for theta in (-0.3, 0.1, 0.4):
        mid = rho * np.array(
            [np.sin(theta) - theta * np.cos(theta), np.cos(theta) + theta * np.sin(theta)]
        )
        axis = np.array([np.cos(theta), -np.sin(theta)])
        for f in forces:
            p = np.array([value(c, theta=theta, rho=rho) for c in f["at"][:2]])
            assert np.allclose(p, mid + rho * theta * axis, atol=1e-12)
