"""Every endpoint that takes request parameters refuses the values no real system has.

/simulate and /precision checked the physical limits at the request's values, /equilibria and
/check/predict did not: a spring written k − 3 at k = 1 (a stiffness of −2, pumping energy in)
was analysed and predicted without a word. Each refusal below is stated from the physics
(k − 3 < 0 at k = 1, a damping coefficient c − 0.2 < 0 at c = 0.1) and paired with a valid
neighbour that must still answer 200, so a test cannot pass by refusing everything.
"""

from __future__ import annotations

import copy

import pytest
from fastapi.testclient import TestClient

from app.main import app

SPRING = {
    "title": "Damped spring",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 5.0, "c": 0.5},
    "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
    "springs": [{"a": "O", "b": "b", "k": "k - 3"}],
    "dampers": [{"a": "O", "b": "b", "c": "c - 0.2"}],
    "initial": {"x": 0.5},
}

ENDPOINTS = {
    "/api/v1/equilibria": {},
    "/api/v1/simulate": {"t_end": 1, "check_sensitivity": False},
    "/api/v1/check/predict": {"quantity": "T", "answer": "m*x_dot^2/2", "t_end": 1},
    "/api/v1/precision": {"methods": ["rk4"], "steps": [0.01], "t_end": 1},
}


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def post(client, url: str, parameters: dict, scene: dict | None = None, scene_id=None):
    where = {"scene_id": scene_id} if scene_id else {"scene": copy.deepcopy(scene)}
    return client.post(url, json={**where, "parameters": parameters, **ENDPOINTS[url]})


def refused(r) -> list[str]:
    assert r.status_code == 422, r.text
    detail = r.json()["detail"]
    assert all(set(e) == {"field", "message"} for e in detail)
    return [e["field"] for e in detail]


@pytest.mark.parametrize("url", ENDPOINTS)
def test_the_valid_neighbour_answers(client, url):
    assert post(client, url, {"k": 4.0, "c": 0.3}, SPRING).status_code == 200


@pytest.mark.parametrize("url", ENDPOINTS)
def test_a_stiffness_negative_at_the_request_values_is_refused(client, url):
    r = post(client, url, {"k": 1.0}, SPRING)
    assert refused(r) == ["springs[0].k"]
    assert "-2" in r.json()["detail"][0]["message"]  # k − 3 at k = 1


@pytest.mark.parametrize("url", ENDPOINTS)
def test_a_damping_coefficient_negative_at_the_request_values_is_refused(client, url):
    assert refused(post(client, url, {"c": 0.1}, SPRING)) == ["dampers[0].c"]


@pytest.mark.parametrize("url", ENDPOINTS)
def test_a_negative_stiffness_parameter_is_named(client, url):
    assert refused(post(client, url, {"k": -5.0}, scene_id="spring_mass_damper")) == [
        "parameters.k"
    ]


@pytest.mark.parametrize(
    "body, field",
    [
        ({"t_end": True}, "t_end"),
        ({"parameters": {"m": True}}, "parameters.m"),
        ({"initial": {"theta": False}}, "initial.theta"),
        ({"method": "rk4", "dt": True}, "dt"),
        ({"rtol": True}, "rtol"),
    ],
)
def test_json_true_is_not_a_number_in_a_share_link(client, body, field):
    """JSON true read as 1.0 would share a state nobody asked for: the share endpoint is as
    strict as /simulate (app/schemas.py's Finite)."""
    r = client.post("/api/v1/export/share", json={"scene_id": "simple_pendulum", **body})
    assert refused(r) == [field]


def test_a_share_link_with_numbers_still_works(client):
    body = {"scene_id": "simple_pendulum", "t_end": 5, "parameters": {"m": 2}, "rtol": 1e-8}
    r = client.post("/api/v1/export/share", json=body)
    assert r.status_code == 200, r.text
    state = client.get(r.json()["api"]).json()
    assert state["t_end"] == 5 and state["parameters"] == {"m": 2.0}


@pytest.mark.parametrize("url", ENDPOINTS)
def test_a_mass_negative_at_the_request_values_is_refused(client, url):
    """m − 2 at m = 1 is a mass of −1: named as the body's mass, not as a singular start."""
    spec = copy.deepcopy(SPRING)
    spec["bodies"][0]["mass"] = "m - 2"
    spec["parameters"]["m"] = 3.0
    assert post(client, url, {"m": 2.5}, spec).status_code == 200
    r = post(client, url, {"m": 1.0}, spec)
    assert refused(r) == ["bodies[0].mass"]
    assert "-1" in r.json()["detail"][0]["message"]
