"""Every analysis endpoint takes a posted spec as well as a built-in id, and answers the same."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from app.main import app

client = TestClient(app)
SPEC = client.get("/api/v1/scenes/simple_pendulum").json()["spec"]


@pytest.mark.parametrize(
    ("path", "extra"),
    [
        ("/api/v1/check", {"quantity": "T", "answer": "1/2 m l^2 theta'^2"}),
        ("/api/v1/equilibria", {"parameters": {"l": 2.0}}),
        ("/api/v1/newton", {}),
    ],
)
def test_posted_spec_answers_like_the_builtin(path, extra):
    posted = client.post(path, json={"scene": SPEC, **extra})
    builtin = client.post(path, json={"scene_id": "simple_pendulum", **extra})
    assert posted.status_code == builtin.status_code == 200
    assert posted.json() == builtin.json()


@pytest.mark.parametrize("path", ["/api/v1/check", "/api/v1/equilibria", "/api/v1/newton"])
def test_unknown_scene_and_bad_spec(path):
    extra = {"quantity": "T", "answer": "m"} if path.endswith("check") else {}
    assert client.post(path, json={"scene_id": "nope", **extra}).status_code == 404
    bad = {**SPEC, "bodies": [{**SPEC["bodies"][0], "mass": "lenght"}]}
    r = client.post(path, json={"scene": bad, **extra})
    assert r.status_code == 422
    assert r.json()["detail"][0]["field"] == "bodies[0].mass"
