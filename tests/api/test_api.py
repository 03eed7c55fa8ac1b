"""The /api/v1 contract as a client sees it: shapes, status codes and field paths of errors."""

from __future__ import annotations

import copy
import os
import statistics
import subprocess
import sys
import time

import httpx
import pytest
from fastapi.testclient import TestClient
from servers import free_port

# The app's error handlers need the engine's ExprError; skip (not error) until expr.py has landed.
from app.main import app  # noqa: E402

PENDULUM = {
    "title": "Pendulum",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "bodies": [
        {"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]},
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def scene_with(**changes) -> dict:
    """The pendulum spec with top-level keys replaced (None deletes the key)."""
    spec = copy.deepcopy(PENDULUM)
    for key, value in changes.items():
        if value is None:
            spec.pop(key)
        else:
            spec[key] = value
    return spec


def fields(response: httpx.Response) -> list[str]:
    assert response.status_code == 422, response.text
    return [d["field"] for d in response.json()["detail"]]


# --- scenes ---------------------------------------------------------------------------------


def test_scene_list_has_every_builtin_with_its_menu_fields(client):
    response = client.get("/api/v1/scenes")
    assert response.status_code == 200
    scenes = response.json()
    assert len(scenes) >= 13
    for scene in scenes:
        assert set(scene) == {"id", "title", "summary", "coordinates"}
        assert scene["title"] and scene["coordinates"]
    assert "simple_pendulum" in {s["id"] for s in scenes}


def test_one_scene_is_its_spec(client):
    response = client.get("/api/v1/scenes/simple_pendulum")
    assert response.status_code == 200
    body = response.json()
    assert body["id"] == "simple_pendulum"
    assert body["spec"]["coordinates"] == ["theta"]
    assert body["spec"]["bodies"][0]["mass"] == "m"


@pytest.mark.parametrize("scene_id", ["no_such_scene", "SIMPLE_PENDULUM", "__init__", "spec.py"])
def test_an_unknown_scene_is_404(client, scene_id):
    response = client.get(f"/api/v1/scenes/{scene_id}")
    assert response.status_code == 404
    assert response.json() == {
        "detail": [
            {
                "field": "scene_id",
                "message": f"unknown scene '{scene_id}' (GET /api/v1/scenes lists the scene ids)",
            }
        ]
    }


def test_a_path_for_a_scene_id_is_404(client):
    assert client.get("/api/v1/scenes/..%2F..%2Fpyproject.toml").status_code == 404


def test_deriving_an_unknown_scene_is_404(client):
    response = client.post("/api/v1/derive", json={"scene_id": "no_such_scene"})
    assert response.status_code == 404
    assert response.json() == {
        "detail": [
            {
                "field": "scene_id",
                "message": "unknown scene 'no_such_scene' (GET /api/v1/scenes lists the scene ids)",
            }
        ]
    }


# --- derive: built-in and posted scenes -----------------------------------------------------


def test_derive_a_builtin_scene(client):
    response = client.post("/api/v1/derive", json={"scene_id": "simple_pendulum"})
    assert response.status_code == 200, response.text
    body = response.json()
    assert body["steps"] and all(step["latex"] for step in body["steps"])
    eom = body["equations"]["eom"]["theta"]
    assert "sin(theta)" in eom and "g" in eom
    assert set(body["latex"]) == set(body["equations"])


def test_derive_a_posted_scene(client):
    response = client.post("/api/v1/derive", json={"scene": PENDULUM})
    assert response.status_code == 200, response.text
    eom = response.json()["equations"]["eom"]["theta"]
    assert "sin(theta)" in eom and "g" in eom


def test_a_posted_scene_past_its_time_budget_is_503(client, monkeypatch):
    monkeypatch.setenv("LAGRANGE_LAB_DERIVE_SECONDS", "0.001")
    # a spec no worker derived before: a derivation kept from an earlier test answers in < 1 ms
    unseen = scene_with(title=f"Never seen {time.time_ns()}")
    response = client.post("/api/v1/derive", json={"scene": unseen})
    assert response.status_code == 503
    (problem,) = response.json()["detail"]
    assert problem["field"] == "scene" and "time budget" in problem["message"]


# --- derive: the request and the spec are checked, errors name their field ------------------


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"scene_id": "simple_pendulum", "scene": PENDULUM}, "scene"),
        ({}, "scene_id"),
        ({"scene_id": "Not An Id"}, "scene_id"),
        ({"scene_id": "simple_pendulum", "extra": 1}, "extra"),
    ],
)
def test_the_request_needs_exactly_one_valid_scene_id_or_scene(client, body, field):
    response = client.post("/api/v1/derive", json=body)
    assert field in fields(response)
    if field in ("scene", "scene_id") and "Not" not in str(body):
        message = response.json()["detail"][0]["message"]
        assert "scene_id" in message and "scene" in message


@pytest.mark.parametrize(
    ("scene", "field"),
    [
        (scene_with(bodies=None), "bodies"),
        (scene_with(coordinates=[]), "coordinates"),
        (scene_with(coordinates=[f"q{i}" for i in range(7)]), "coordinates"),
        (
            scene_with(bodies=[{"name": "bob", "mass": "m", "position": ["l"]}]),
            "bodies[0].position",
        ),
        (scene_with(coordinates=["1x"]), "coordinates[0]"),
        (scene_with(bodies=[{**PENDULUM["bodies"][0], "name": "theta"}]), "bodies[0].name"),
    ],
)
def test_a_malformed_scene_is_422_with_field_paths(client, scene, field):
    assert field in fields(client.post("/api/v1/derive", json={"scene": scene}))


def test_a_nan_parameter_is_422(client):
    # Python's json accepts a bare NaN; the API must not let it into the algebra.
    text = '{"scene": {"coordinates": ["x"], "parameters": {"m": NaN},'
    text += ' "bodies": [{"name": "b", "mass": "m", "position": ["x", 0]}]}}'
    response = client.post(
        "/api/v1/derive", content=text, headers={"content-type": "application/json"}
    )
    assert any(f.startswith("parameters") for f in fields(response))
    assert "finite" in response.text


def test_invalid_json_is_422_on_the_body(client):
    response = client.post(
        "/api/v1/derive", content="{not json", headers={"content-type": "application/json"}
    )
    assert fields(response) == ["body"]


def test_an_unknown_name_in_an_expression_is_422_at_its_field(client):
    body = {**PENDULUM["bodies"][0], "position": ["lenght*sin(theta)", "-l*cos(theta)", 0]}
    response = client.post("/api/v1/derive", json={"scene": scene_with(bodies=[body])})
    detail = response.json()["detail"]
    assert response.status_code == 422, response.text
    assert detail[0]["field"] == "bodies[0].position[0]"
    assert "lenght" in detail[0]["message"]


@pytest.mark.parametrize(
    "mass",
    ["__import__('os').system('ls')", "m.__class__", "lambda: 1", "m; import os", "exec('1')"],
)
def test_code_in_an_expression_is_refused(client, mass):
    body = {**PENDULUM["bodies"][0], "mass": mass}
    response = client.post("/api/v1/derive", json={"scene": scene_with(bodies=[body])})
    assert "bodies[0].mass" in fields(response)


def test_a_100_kb_expression_is_refused_fast(client):
    body = {**PENDULUM["bodies"][0], "mass": "m+" * 50_000 + "m"}
    start = time.perf_counter()
    response = client.post("/api/v1/derive", json={"scene": scene_with(bodies=[body])})
    assert time.perf_counter() - start < 1.0
    assert "bodies[0].mass" in fields(response)
    assert len(response.content) < 2_000  # the offending input is not echoed back


def test_a_huge_body_is_refused_unread(client):
    response = client.post(
        "/api/v1/derive",
        content=b"{" + b" " * (2 * 1024 * 1024) + b"}",
        headers={"content-type": "application/json"},
    )
    assert response.status_code == 413


# --- the service as a whole -----------------------------------------------------------------


def test_openapi_documents_the_api(client):
    schema = client.get("/openapi.json").json()
    assert "/api/v1/derive" in schema["paths"]
    assert "/api/v1/scenes" in schema["paths"]
    derive = schema["paths"]["/api/v1/derive"]["post"]
    assert "DeriveResponse" in str(derive["responses"]["200"])
    assert client.get("/docs").status_code == 200


def test_still_healthy_after_all_of_the_above(client):
    response = client.get("/healthz")
    assert response.status_code == 200
    assert response.json()["status"] == "ok"


def children_of(pid: int) -> list[str]:
    """Child pids of every thread of ``pid``, zombies included (Linux /proc)."""
    tasks = f"/proc/{pid}/task"
    if not os.path.isdir(tasks):
        return []
    out: list[str] = []
    for tid in os.listdir(tasks):
        with open(f"{tasks}/{tid}/children") as f:
            out += f.read().split()
    return out


def test_a_real_server_is_fast_warm_and_survives_bad_and_runaway_requests(tmp_path):
    """Under uvicorn itself (its signal handlers, threadpool, real HTTP), not the test client."""
    port = free_port()
    env = {**os.environ, "LAGRANGE_LAB_DERIVE_SECONDS": "0.001"}
    server = subprocess.Popen(
        [sys.executable, "-m", "app", "serve", "--port", str(port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=(tmp_path / "server.log").open("w"),
    )
    try:
        base = f"http://127.0.0.1:{port}"
        deadline = time.monotonic() + 60
        while True:
            try:
                if httpx.get(f"{base}/healthz", timeout=1, trust_env=False).status_code == 200:
                    break
            except httpx.TransportError:
                pass
            alive = server.poll() is None and time.monotonic() < deadline
            assert alive, (tmp_path / "server.log").read_text()
            time.sleep(0.2)
        helpers = sorted(children_of(server.pid))  # the worker pool's forkserver and tracker
        with httpx.Client(base_url=base, timeout=120, trust_env=False) as http:
            builtin = {"scene_id": "simple_pendulum"}
            assert http.post("/api/v1/derive", json=builtin).status_code == 200  # warms it
            timings = []
            for _ in range(20):
                start = time.perf_counter()
                assert http.post("/api/v1/derive", json=builtin).status_code == 200
                timings.append(time.perf_counter() - start)
            # ~1.5 ms on an idle machine (python -m benchmarks derive measures it); the
            # bound here only proves the warm path is a lookup, not a derivation (~100 ms+)
            assert statistics.median(timings) < 0.05, timings
            # a spec never derived before: a cached derivation needs no budget (it answers at once)
            unseen = scene_with(title=f"Runaway {time.time_ns()}")
            for _ in range(3):
                start = time.perf_counter()
                assert http.post("/api/v1/derive", json={"scene": unseen}).status_code == 503
                # the pool kills the worker at its deadline: no grace period to wait out
                assert time.perf_counter() - start < 3.0
            assert http.post("/api/v1/derive", json={}).status_code == 422
            bad = scene_with(coordinates=["1x"])
            assert http.post("/api/v1/derive", json={"scene": bad}).status_code == 422
            assert http.get("/healthz").status_code == 200
        assert server.poll() is None
        left = sorted(children_of(server.pid))
        assert left == helpers, "the timed-out derivations left processes behind"
    finally:
        server.terminate()
        server.wait(timeout=30)
