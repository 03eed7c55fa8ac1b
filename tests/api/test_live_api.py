"""The live equations over HTTP (app/routes/scenes.py): a built-in scene's module under its
content hash, revalidated by ETag, a posted spec's module printed in the pool, and the catalog's
drawings in one answer."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.scenes import list_scenes

PENDULUM = {
    "title": "Pendulum",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]}],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def test_a_scenes_module_is_served_as_javascript_under_its_hash(client):
    meta = client.get("/api/v1/scenes/double_pendulum/live")
    assert meta.status_code == 200 and meta.headers["cache-control"] == "no-cache"
    body = meta.json()
    assert body["coordinates"] == ["theta1", "theta2"]
    assert body["points"] == ["O", "bob1", "bob2"]
    module = client.get(body["module"])
    assert module.headers["content-type"].startswith("text/javascript")
    assert "immutable" in module.headers["cache-control"]
    assert "export function rhs(t, y, p, out)" in module.text
    again = client.get(body["module"], headers={"if-none-match": module.headers["etag"]})
    assert again.status_code == 304 and again.content == b""
    # without the current hash the module is not cached for a year
    stale = client.get("/api/v1/scenes/double_pendulum/live.js?v=old")
    assert stale.headers["cache-control"] == "no-cache"
    assert client.get("/api/v1/scenes/nowhere/live").status_code == 404


def test_a_posted_specs_module_is_printed_for_it(client):
    r = client.post("/api/v1/scenes/live", json={"scene": PENDULUM})
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["coordinates"] == ["theta"] and sorted(body["parameters"]) == ["g", "l", "m"]
    module = client.get(body["module"])
    assert module.status_code == 200 and "export function places" in module.text
    assert client.get("/api/v1/scenes/live/0123456789abcdef.js").status_code == 404
    bad = client.post("/api/v1/scenes/live", json={"scene": {**PENDULUM, "coordinates": ["x"]}})
    assert bad.status_code == 422


def test_the_catalog_brings_every_scene_with_its_drawing_run(client):
    r = client.get("/api/v1/scenes/catalog")
    assert r.status_code == 200
    entries = r.json()
    assert [e["id"] for e in entries] == [s["id"] for s in list_scenes()]  # teaching order
    for e in entries:
        assert e["spec"]["coordinates"] == e["coordinates"]
        run = e["run"]
        assert run is not None, e["id"]
        n = len(run["t"])  # 1 s at 30 fps, or less where a stop ends the run
        assert 2 <= n <= 31 and run["t"][1] == pytest.approx(1 / 30), e["id"]
        for body in e["spec"]["bodies"]:
            assert len(run["positions"][body["name"]]["x"]) == n
    assert (
        client.get(
            "/api/v1/scenes/catalog", headers={"if-none-match": r.headers["etag"]}
        ).status_code
        == 304
    )
