"""Physical limits and lax input are refused with a 422 naming the exact field.

Each value below is one no real system has (a negative stiffness pumps energy in; an inertia
tensor outside the triangle inequality has no mass distribution), or one a client cannot have
meant (JSON true for a number, a unit nobody can read). The expected refusals are stated here
from the physics, and each is checked against a neighbouring valid spec that must still run, so
a test cannot pass by refusing everything.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.model import _inertia_errors

SPRING = {
    "title": "Spring",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 1.0},
    "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
    "springs": [{"a": "O", "b": "b", "k": "k"}],
    "initial": {"x": 0.5},
}

ROD = {
    "title": "Rod",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "theta"}],
    "bodies": [
        {
            "name": "rod",
            "kind": "rigid_body",
            "mass": "m",
            "frame": "R",
            "position": {"frame": "R", "components": [0, "-l/2", 0]},
            "inertia": {"ixx": "m*l**2/12", "iyy": 0, "izz": "m*l**2/12"},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    "initial": {"theta": 1.0},
}


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def simulate(client, spec: dict, **extra):
    return client.post(
        "/api/v1/simulate",
        json={"scene": spec, "t_end": 1, "check_sensitivity": False, **extra},
    )


def fields(r) -> list[str]:
    assert r.status_code == 422, r.text
    return [e["field"] for e in r.json()["detail"]]


def with_(base: dict, path: tuple, value) -> dict:
    spec = copy.deepcopy(base)
    target = spec
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return spec


def test_the_valid_neighbours_run(client):
    assert simulate(client, SPRING).status_code == 200
    assert simulate(client, ROD).status_code == 200
    damped = with_(SPRING, ("dampers",), [{"a": "O", "b": "b", "c": 0.3}])
    assert simulate(client, damped).status_code == 200


@pytest.mark.parametrize(
    "path, value, field",
    [
        (("springs", 0, "k"), -5, "springs[0].k"),
        (("springs", 0, "k"), "k - 3", "springs[0].k"),  # -2 at k = 1
        (("springs", 0, "k"), "-k", "springs[0].k"),
        (("springs", 0, "rest_length"), -1, "springs[0].rest_length"),
        (("dampers",), [{"a": "O", "b": "b", "c": -1}], "dampers[0].c"),
        (("gravity",), {"acceleration": -9.81, "direction": [0, -1, 0]}, "gravity.acceleration"),
    ],
)
def test_negative_magnitudes_written_as_numbers_or_expressions_are_refused(
    client, path, value, field
):
    assert fields(simulate(client, with_(SPRING, path, value))) == [field]


def test_a_negative_damping_coefficient_would_pump_energy_in(client):
    """Why c < 0 is refused: integrated by hand, ẍ = −kx − cẋ with c = −1 gains energy."""
    x, v, dt = 0.5, 0.0, 1e-3
    for _ in range(5000):
        v += dt * (-x + v)  # k = 1, c = −1
        x += dt * v
    assert (x * x + v * v) / 2 > 10 * 0.5**2 / 2


def test_an_expression_negative_only_at_request_values_is_refused_there(client):
    spec = with_(SPRING, ("springs", 0, "k"), "k - 3")
    spec["parameters"]["k"] = 5.0
    assert simulate(client, spec).status_code == 200
    assert fields(simulate(client, spec, parameters={"k": 1.0})) == ["springs[0].k"]


@pytest.mark.parametrize(
    "inertia, field",
    [
        ({"ixx": "-1", "iyy": 1, "izz": 1}, "bodies[0].inertia.ixx"),
        ({"ixx": 0, "iyy": 0, "izz": -0.5}, "bodies[0].inertia.izz"),
        ({"ixx": 0.1, "iyy": 0.1, "izz": 5}, "bodies[0].inertia"),  # 5 > 0.1 + 0.1
        ({"ixx": 1, "iyy": 1, "izz": 1, "ixy": 5}, "bodies[0].inertia"),  # eigenvalue 1 − 5
    ],
)
def test_impossible_inertia_tensors_are_refused(client, inertia, field):
    assert fields(simulate(client, with_(ROD, ("bodies", 0, "inertia"), inertia))) == [field]


def test_the_inertia_limits_agree_with_a_sampled_mass_distribution():
    """Any cloud of point masses has a PSD central tensor whose principal moments obey the
    triangle inequality: the limits refuse nothing a real body has."""
    rng = np.random.default_rng(1)
    for _ in range(200):
        r = rng.normal(size=(7, 3)) * rng.uniform(0.01, 3, size=3)
        m = rng.uniform(0.1, 2, size=7)
        r -= (m[:, None] * r).sum(0) / m.sum()
        parts = [mi * (ri @ ri * np.eye(3) - np.outer(ri, ri)) for mi, ri in zip(m, r, strict=True)]
        tensor = sum(parts)
        low, mid, high = np.linalg.eigvalsh(tensor)
        assert low >= -1e-12 and high <= low + mid + 1e-12
        entries = {
            "ixx": tensor[0, 0],
            "iyy": tensor[1, 1],
            "izz": tensor[2, 2],
            "ixy": tensor[0, 1],
            "iyz": tensor[1, 2],
            "izx": tensor[2, 0],
        }
        assert _inertia_errors("bodies[0].inertia", "b's inertia", entries) == []


@pytest.mark.parametrize("field", ["t_end", "fps", "dt", "rtol", "atol"])
def test_json_true_is_not_a_number_in_a_request(client, field):
    body = {"scene_id": "simple_pendulum", "method": "rk4", "dt": 0.01, field: True}
    r = client.post("/api/v1/simulate", json=body)
    assert fields(r) == [field]


@pytest.mark.parametrize(
    "path, value, field",
    [
        (("parameters", "m"), True, "parameters.m"),
        (("initial", "x"), True, "initial.x"),
        (("bodies", 0, "mass"), True, "bodies[0].mass"),
        (("springs", 0, "k"), False, "springs[0].k"),
        (("units",), {"x": "banana"}, "units.x"),
        (("units",), {"m": r"kg\input{/etc/passwd}"}, "units.m"),
        (("forces",), [{"on": "O", "vector": [1, 0, 0]}], "forces[0].on"),
        (
            ("frames",),
            [{"name": "A", "axis": "z", "angle": "x", "unit_vectors": ["e", "e", "e"]}],
            "frames[0].unit_vectors",
        ),
    ],
)
def test_lax_input_in_a_spec_is_refused_naming_the_field(client, path, value, field):
    r = simulate(client, with_(SPRING, path, value))
    assert fields(r) == [field]
    assert not any("Value error" in e["message"] for e in r.json()["detail"])


def test_readable_units_and_integers_still_pass(client):
    spec = with_(SPRING, ("units",), {"x": "m", "k": "N/m", "m": "kg"})
    spec["parameters"] = {"m": 1, "k": 2}  # integers are numbers
    assert simulate(client, spec).status_code == 200


ROOT = {
    "title": "Bead on a root curve",
    "coordinates": ["th"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "bodies": [{"name": "b", "mass": "m", "position": ["l*sqrt(th)", "-l*th", 0]}],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    "initial": {"th": 0.5},
}


@pytest.mark.parametrize("th", [0.0, -0.1])
def test_a_start_at_a_domain_end_names_the_coordinate_not_the_units(client, th):
    """x = l√θ: ẋ = l θ̇ /(2√θ), so M = m l²(1/(4θ) + 1) is infinite at θ = 0 and undefined
    below: the start's coordinate is at fault, not the size of the parameters."""
    r = simulate(client, ROOT, initial={"th": th})
    assert fields(r) == ["initial.th"]
    message = r.json()["detail"][0]["message"]
    assert "domain" in message and "th > 0" in message and "units" not in message


def test_inside_the_domain_the_root_curve_runs(client):
    assert simulate(client, ROOT).status_code == 200


def test_the_derivation_refuses_the_same_limits(client):
    """/derive builds the model at the spec's own values: the refusal is there too."""
    spec = with_(SPRING, ("springs", 0, "k"), "k - 3")
    r = client.post("/api/v1/derive", json={"scene": spec})
    assert fields(r) == ["springs[0].k"]
    rod = with_(ROD, ("bodies", 0, "inertia"), {"ixx": 0, "iyy": 0, "izz": -0.5})
    r = client.post("/api/v1/derive", json={"scene": rod})
    assert fields(r) == ["bodies[0].inertia.izz"]
