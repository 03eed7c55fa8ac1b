"""Sharing and export against the hostile play-test: a share is checked the way the run it opens
is checked (the same field and reason as /simulate), errors speak of the token and the query,
never of Python (no JSON decoder positions, recursion limits or class names), and an export's
query string is read whole: a key it does not read, a key given twice, or a number the page would
not read the same way is a 422 naming it."""

from __future__ import annotations

import base64
import json
import zlib

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.export_share import page_run, run_problems
from mechanics.simulate import SimulationRequest

client = TestClient(app)

#: Words of Python's, not of the app's: none may reach an answer.
PYTHON_WORDS = ["Expecting value", "char ", "recursion", "instance of", "should match pattern"]
PYTHON_WORDS += ["Traceback", "float object", "NoneType", "Error(", "SceneSpec"]


def token_of(document: object) -> str:
    raw = zlib.compress(document if isinstance(document, bytes) else json.dumps(document).encode())
    return "z" + base64.urlsafe_b64encode(raw).decode().rstrip("=")


def simulate_refusal(body: dict) -> list[dict[str, str]]:
    r = client.post("/api/v1/simulate", json=body)
    assert r.status_code == 422, r.text
    return r.json()["detail"]


# --- the run a share opens: refused as /simulate refuses it -------------------------------------


@pytest.mark.parametrize(
    "state, field",
    [
        # M = m l² = 0: no inertia (the pendulum's mass matrix by hand)
        ({"scene_id": "simple_pendulum", "parameters": {"m": 0.0}}, "parameters.m"),
        ({"scene_id": "simple_pendulum", "parameters": {"l": 0.0}}, "parameters.l"),
        # r is the cone's radial distance, declared positive: r = 0 is its vertex
        ({"scene_id": "particle_in_cone", "initial": {"r": 0.0}}, "initial.r"),
        # T = ½ m l² θ̇² overflows a double for θ̇ = 1e200
        ({"scene_id": "simple_pendulum", "initial": {"theta_dot": 1e200}}, "initial.theta_dot"),
    ],
)
def test_a_state_the_run_refuses_is_refused_with_the_runs_own_words(state, field):
    body = {**state, "fps": 30.0, "t_end": 10.0, "rtol": 1e-9, "atol": 1e-9}
    expected = simulate_refusal(body)
    assert field in {p["field"] for p in expected}
    problems = run_problems(state["scene_id"], None, page_run(state))
    assert problems == expected


def test_an_atwood_machine_past_its_pulley_is_refused_like_the_run():
    """x = 100 m puts mass 2 past the pulley (its rope is ~1.3 m long in the default run)."""
    state = {"scene_id": "atwood_machine", "initial": {"x": 100.0}}
    expected = simulate_refusal({**state, "fps": 30.0, "rtol": 1e-9, "atol": 1e-9})
    assert run_problems("atwood_machine", None, page_run(state)) == expected
    assert "pulley" in expected[0]["message"]


def test_an_honest_state_has_no_run_problems():
    for state in (
        {"scene_id": "double_pendulum", "parameters": {"m2": 2.0}, "initial": {"theta1": 1.0}},
        {"scene_id": "simple_pendulum", "method": "rk4"},  # the page's dt of 0.01 s
        {"scene_id": "elastic_pendulum", "initial": {"r": 1.25}},
    ):
        assert run_problems(state["scene_id"], None, page_run(state)) == [], state


def test_the_page_run_of_a_state_is_the_pages_request():
    """static/js/scene.js asks for 30 samples a second; integrator.js's defaults are rtol = atol
    = 1e-9 and dt = 0.01 s."""
    adaptive = page_run({"scene_id": "simple_pendulum", "t_end": 7.5, "rtol": 1e-6})
    assert (adaptive.fps, adaptive.t_end, adaptive.rtol, adaptive.atol) == (30.0, 7.5, 1e-6, 1e-6)
    assert adaptive.dt is None
    fixed = page_run({"scene_id": "simple_pendulum", "method": "euler"})
    assert (fixed.method, fixed.dt) == ("euler", 0.01)
    assert isinstance(fixed, SimulationRequest)


def test_a_share_outside_the_pages_t_end_range_is_refused():
    """The page's t_end box clamps to 0.1–120 s (integrator.js): such a link would not open as
    shared."""
    for t_end in (0.0, 121.0, 1000.0):
        r = client.post(
            "/api/v1/export/share", json={"scene_id": "simple_pendulum", "t_end": t_end}
        )
        assert r.status_code == 422 and r.json()["detail"][0]["field"] == "t_end"


# --- no Python in the answers --------------------------------------------------------------------


@pytest.mark.parametrize(
    "token, says",
    [
        (token_of(b'{"a":'), "breaks off"),
        (token_of(b'{"a" 1}'), "at character 6"),  # the 1-based place of the '1'
        (token_of(b"[" * 100_000), "nested too deeply"),
        (token_of(b"\xff\xfe"), "not UTF-8"),
        (token_of({"scene": []}), "valid dictionary"),
        (token_of({"scene_id": "simple_pendulum", "initial": {"θ": 1}}), "not a name"),
    ],
)
def test_a_malformed_token_is_told_without_python_words(token, says):
    for url in (f"/api/v1/export/share/{token}", f"/s/{token}"):
        r = client.get(url, follow_redirects=False)
        assert r.status_code == 422, r.text
        text = r.text
        assert says in text
        for word in PYTHON_WORDS:
            assert word not in text, (word, text)


def test_a_bad_name_in_a_posted_share_is_told_in_words():
    r = client.post(
        "/api/v1/export/share", json={"scene_id": "simple_pendulum", "initial": {"θ": 1.0}}
    )
    assert r.status_code == 422
    (problem,) = r.json()["detail"]
    assert "not a name" in problem["message"]
    assert "pattern" not in problem["message"] and "^[" not in problem["message"]


# --- an export's query string is read whole ------------------------------------------------------

BASE = "/api/v1/export/scenes/simple_pendulum"


@pytest.mark.parametrize(
    "url, field",
    [
        (f"{BASE}/trajectory.csv?bogus=1", "bogus"),
        (f"{BASE}/trajectory.json?theta=1&tehta_dot=2", "tehta_dot"),
        (f"{BASE}/run.py?M=2", "M"),  # the pendulum's mass is m
        (f"{BASE}/derivation.tex?m=2", "m"),  # the derivation is symbolic
        (f"{BASE}/spec.toml?format=json", "format"),
    ],
)
def test_an_export_names_the_query_key_it_does_not_read(url, field):
    r = client.get(url)
    assert r.status_code == 422, r.text
    (problem,) = r.json()["detail"]
    assert problem["field"] == field
    assert f"unknown query parameter '{field}'" in problem["message"]


def test_a_posted_export_names_a_query_key_it_does_not_read():
    body = {"scene_id": "simple_pendulum", "t_end": 1.0}
    r = client.post("/api/v1/export/trajectory?format=json&fromat=csv", json=body)
    assert r.status_code == 422
    assert r.json()["detail"] == [
        {
            "field": "fromat",
            "message": "unknown query parameter 'fromat': this export reads format (csv or json) "
            "only",
        }
    ]


def test_the_pages_own_settings_are_passed_over_not_refused():
    """The page links run.py and the trajectory with its whole query (controls.js writeQuery):
    lecture, step, compare, method_b and phase are its own and change nothing in the run."""
    plain = client.get(f"{BASE}/trajectory.json?theta=1.5&t_end=2")
    page = client.get(
        f"{BASE}/trajectory.json?theta=1.5&t_end=2&lecture=1&step=3&compare=1&method_b=rk4"
        "&phase=theta"
    )
    assert plain.status_code == page.status_code == 200, page.text
    assert plain.json()["q"] == page.json()["q"]


@pytest.mark.parametrize(
    "query, field",
    [
        ("theta=1_0", "theta"),  # Python's float() reads 10; the page's Number() reads NaN
        ("theta=%201", "theta"),
        ("m=infinity", "m"),
        ("m=1&m=2", "m"),  # which one?
    ],
)
def test_a_value_the_page_would_not_read_the_same_way_is_refused(query, field):
    r = client.get(f"{BASE}/trajectory.csv?{query}")
    assert r.status_code == 422, r.text
    (problem,) = r.json()["detail"]
    assert problem["field"] == field


def test_a_bad_tolerance_is_said_once():
    r = client.get(f"{BASE}/trajectory.csv?tol=abc")
    assert r.status_code == 422
    assert r.json()["detail"] == [{"field": "tol", "message": "must be a finite number, not 'abc'"}]


# --- with the share routes wired to run_problems (patch/share_run_check.patch) ----------------


@pytest.mark.parametrize(
    "state, field",
    [
        ({"scene_id": "simple_pendulum", "parameters": {"m": 0.0}}, "parameters.m"),
        ({"scene_id": "particle_in_cone", "initial": {"r": 0.0}}, "initial.r"),
        ({"scene_id": "atwood_machine", "initial": {"x": 100.0}}, "initial"),
    ],
)
def test_a_share_of_a_state_the_run_refuses_is_refused_the_same_way(state, field):
    expected = simulate_refusal({**state, "fps": 30.0, "rtol": 1e-9, "atol": 1e-9})
    assert field in {p["field"] for p in expected}
    r = client.post("/api/v1/export/share", json=state)
    assert r.status_code == 422 and r.json()["detail"] == expected
    token = token_of(state)
    for url in (f"/api/v1/export/share/{token}", f"/s/{token}"):
        r = client.get(url, follow_redirects=False)
        assert r.status_code == 422
        assert r.json()["detail"] == [{**p, "field": f"token.{p['field']}"} for p in expected]


def test_a_posted_specs_share_is_checked_by_its_own_run():
    from mechanics.scenes import load_scene

    spec = load_scene("simple_pendulum")
    r = client.post("/api/v1/export/share", json={"scene": spec, "parameters": {"m": 0.0}})
    assert r.status_code == 422
    assert r.json()["detail"][0]["field"] == "parameters.m"
    assert client.post("/api/v1/export/share", json={"scene": spec}).status_code == 200
