"""Physical limits written in t or a coordinate: refused at the start, warned along the run.

A stiffness k (x − 1), a gravity g (t − 1) or a mass m (t − 2) is a number only once t and the
state are given. At t = 0 and the initial state the values below are computed here by hand;
along the run the time a limit turns negative is found from the returned samples, and the
inertia example's M(t) = I_zz(t) + m (l/2)² is worked out by hand.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate

client = TestClient(app)


def _post(scene: dict, **kw) -> tuple[int, dict]:
    body = {"scene": scene, "t_end": 5, "check_sensitivity": False, **kw}
    r = client.post("/api/v1/simulate", json=body)
    return r.status_code, r.json()


def _fields(body: dict) -> list[str]:
    text = str(body)
    return [
        f
        for f in (
            "springs[0].k",
            "springs[0].rest_length",
            "dampers[0].c",
            "gravity.acceleration",
            "bodies[0].mass",
        )
        if f in text
    ]


def _smd(path: str, value: str) -> dict:
    s = copy.deepcopy(load_scene("spring_mass_damper"))
    part, i, key = path.split(".")
    s[part][int(i)][key] = value
    return s


# spring_mass_damper: k = 10, c = 0.4, L0 = 1, x0 = 0.3 (values at t = 0 by hand)
@pytest.mark.parametrize(
    ("path", "value", "field", "at_start"),
    [
        ("springs.0.k", "k*(t-1)", "springs[0].k", -10.0),
        ("springs.0.k", "k*(x-1)", "springs[0].k", -7.0),
        ("dampers.0.c", "c*(t-1)", "dampers[0].c", -0.4),
        ("dampers.0.c", "c*(x-1)", "dampers[0].c", -0.28),
        ("springs.0.rest_length", "L0*(t-1)", "springs[0].rest_length", -1.0),
    ],
)
def test_negative_at_the_start_is_a_422_naming_the_field(path, value, field, at_start):
    code, body = _post(_smd(path, value))
    assert code == 422, body
    assert _fields(body) == [field]
    assert f"{at_start:g}" in str(body)
    # the neighbour, positive at the start and along a short run, still runs
    code, body = _post(_smd(path, value.replace("-1)", "+1)")), t_end=1)
    assert code == 200, body


@pytest.mark.parametrize("value", ["g*(t-1)", "g*(theta-3)"])
def test_gravity_negative_at_the_start(value):
    s = copy.deepcopy(load_scene("simple_pendulum"))  # theta0 = 2
    s["gravity"]["acceleration"] = value
    code, body = _post(s)
    assert code == 422 and _fields(body) == ["gravity.acceleration"], body


@pytest.mark.parametrize(("value", "mass"), [("m*(t-2)", -2.0), ("m*(theta-2)", -1.0)])
def test_mass_negative_at_the_start_names_the_body(value, mass):
    s = copy.deepcopy(load_scene("simple_pendulum"))
    s["initial"]["theta"] = 1.0
    s["bodies"][0]["mass"] = value
    code, body = _post(s)
    assert code == 422, body
    assert _fields(body) == ["bodies[0].mass"]
    assert f"{mass:g}" in str(body) and "singular for every state" not in str(body)


def test_stiffness_turning_negative_along_the_run_is_named_with_its_time():
    s = _smd("springs.0.k", "k*(1 - t/3)")  # negative for t > 3 s exactly
    d = simulate(None, s, SimulationRequest(t_end=6, check_sensitivity=False))
    said = [w for w in d["warnings"] if "springs[0].k" in w]
    assert len(said) == 1, d["warnings"]
    t = np.array(d["t"])
    first = float(t[t > 3][0])  # the first sample past t = 3
    assert f"t = {first:.3g} s" in said[0]
    # a run that stays positive says nothing
    d = simulate(None, _smd("springs.0.k", "k*(1 + t/3)"), SimulationRequest(t_end=6))
    assert not [w for w in d["warnings"] if "springs[0].k" in w]


def test_a_coordinate_dependent_stiffness_turning_negative_is_found_from_the_samples():
    s = _smd("springs.0.k", "k*(1 - 4*x)")  # x0 = 0.3: k (1 − 1.2) = −2 at the start
    code, body = _post(s)
    assert code == 422 and _fields(body) == ["springs[0].k"] and "-2" in str(body)
    s = _smd("springs.0.k", "k*(1 + 5*x)")  # 50 at the start, negative where x < −1/5
    d = simulate(None, s, SimulationRequest(t_end=5, check_sensitivity=False))
    x, t = np.array(d["q"]["x"]), np.array(d["t"])
    assert (x < -0.2).any()  # the swing reaches it
    said = [w for w in d["warnings"] if "springs[0].k" in w]
    assert len(said) == 1 and f"t = {float(t[x < -0.2][0]):.3g} s" in said[0], d["warnings"]


def test_inertia_crossing_zero_is_named_not_told_as_a_blow_up():
    m, length = 1.0, 1.0
    rod = {
        "title": "rod",
        "coordinates": ["theta"],
        "parameters": {"m": m, "l": length, "g": 9.81, "a": 1.0},
        "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "theta"}],
        "bodies": [
            {
                "name": "rod",
                "kind": "rigid_body",
                "mass": "m",
                "position": {"frame": "R", "components": [0, "-l/2", 0]},
                "frame": "R",
                "inertia": {"ixx": "a", "iyy": "a", "izz": "a*cos(t)"},
            }
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
        "initial": {"theta": 1.0, "theta_dot": 0.0},
    }
    code, d = _post(rod, t_end=3, method="RK45", rtol=1e-3)
    assert code == 200, d
    # by hand: M(t) = cos t + m (l/2)² is 0 at t = acos(−1/4); the run cannot pass it
    singular = math.acos(-m * (length / 2) ** 2)
    assert d["t"][-1] <= singular + 1e-6
    said = [w for w in d["warnings"] if "bodies[0].inertia.izz" in w]
    assert len(said) == 1, d["warnings"]
    t = np.array(d["t"])
    assert f"t = {float(t[t > math.pi / 2][0]):.3g} s" in said[0]  # izz = cos t < 0 past π/2
    text = " ".join(d["warnings"])
    assert "blow-up" not in text and "feeds energy" not in text


def test_mass_reaching_zero_at_a_failed_step_is_named():
    s = copy.deepcopy(load_scene("simple_pendulum"))
    s["bodies"][0]["mass"] = "m*(1 - t/2)"  # 0 at t = 2 s exactly
    d = simulate(None, s, SimulationRequest(t_end=5, check_sensitivity=False))
    said = [w for w in d["warnings"] if "bodies[0].mass" in w]
    assert len(said) == 1, d["warnings"]
    assert "blow-up" not in " ".join(d["warnings"])
