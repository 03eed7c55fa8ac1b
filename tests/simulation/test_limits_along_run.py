"""Physical limits written in t or a coordinate: refused at the start, warned along the run.

A stiffness k (x − 1) or a gravity g (t − 1) is a number only once t and the state are given.
At t = 0 and the initial state the values below are computed here by hand; along the run the
time a limit turns negative is found from the returned samples. A mass or an inertia written in
t or a coordinate (m (t − 2), I_zz = a cos t) is no longer run at all: Lagrange's equations need
constant masses (issue 23, item 6), and tests/spec/test_variable_mass.py posts those same specs and
expects the 422 naming their field.
"""

from __future__ import annotations

import copy

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
