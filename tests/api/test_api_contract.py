"""The API contract of issue 12, item 5: enums in OpenAPI, one error shape, the output rate bounded
by samples, one settings object, and plain numbers in every answer (LSODA's stats were numpy)."""

from __future__ import annotations

import asyncio
import json
import re
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from app.errors import budget_exceeded, error_body
from app.main import app
from app.settings import Settings
from mechanics.budget import BudgetExceeded
from mechanics.check import QUANTITIES
from mechanics.integrators import METHODS
from mechanics.simulate import MAX_SAMPLES, SimulationRequest, simulate

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def one_error(response, status: int) -> dict[str, str]:
    """The body of an error answer, in the one shape, with one problem."""
    assert response.status_code == status, response.text
    body = response.json()
    assert set(body) == {"detail"} and len(body["detail"]) == 1, body
    (problem,) = body["detail"]
    assert set(problem) == {"field", "message"}
    return problem


# --- enums --------------------------------------------------------------------------------------


def test_method_and_quantity_are_enums_of_the_registry_in_openapi(client):
    schemas = client.get("/openapi.json").json()["components"]["schemas"]
    assert schemas["SimulateRequest"]["properties"]["method"]["enum"] == list(METHODS)
    assert schemas["CheckRequest"]["properties"]["quantity"]["enum"] == list(QUANTITIES)


@pytest.mark.parametrize(
    ("path", "body", "field"),
    [
        ("/api/v1/simulate", {"scene_id": "simple_pendulum", "method": "lsoda"}, "method"),
        ("/api/v1/simulate", {"scene_id": "simple_pendulum", "method": 4}, "method"),
        (
            "/api/v1/check",
            {"scene_id": "simple_pendulum", "quantity": "H", "answer": "0"},
            "quantity",
        ),
    ],
)
def test_an_unknown_enum_value_is_a_422_naming_the_field(client, path, body, field):
    problem = one_error(client.post(path, json=body), 422)
    assert problem["field"] == field
    assert "'DOP853'" in problem["message"] or "'momentum'" in problem["message"]


# --- one error shape ----------------------------------------------------------------------------


def test_an_unknown_scene_is_a_404_naming_scene_id(client):
    for response in (
        client.get("/api/v1/scenes/no_such_scene"),
        client.post("/api/v1/derive", json={"scene_id": "no_such_scene"}),
        client.post("/api/v1/simulate", json={"scene_id": "no_such_scene"}),
        client.post("/api/v1/equilibria", json={"scene_id": "no_such_scene"}),
    ):
        problem = one_error(response, 404)
        assert problem == {
            "field": "scene_id",
            "message": "unknown scene 'no_such_scene' (GET /api/v1/scenes lists the scene ids)",
        }


def test_a_path_that_names_no_route_is_a_404_naming_the_path(client):
    assert one_error(client.get("/api/v1/no_such_thing"), 404)["field"] == "path"


def test_a_derivation_past_its_time_budget_is_a_503_naming_the_scene():
    # a thread of its own: the browser tests' Playwright keeps an event loop running in this one
    with ThreadPoolExecutor(1) as pool:
        coroutine = budget_exceeded(None, BudgetExceeded("time", "past 20 s"))
        response = pool.submit(asyncio.run, coroutine).result()
    assert response.status_code == 503
    assert json.loads(response.body) == error_body("scene", "time budget exceeded: past 20 s")


def test_openapi_documents_every_error_in_the_one_shape(client):
    document = client.get("/openapi.json").json()
    shape = document["components"]["schemas"]["ValidationErrors"]
    assert shape["properties"]["detail"]["type"] == "array"
    ref = {"$ref": "#/components/schemas/ValidationErrors"}
    expected = {
        "/api/v1/derive": {"404", "413", "422", "503"},
        "/api/v1/simulate": {"404", "413", "422", "503"},
        "/api/v1/check": {"404", "413", "422"},
        "/api/v1/equilibria": {"404", "413", "422"},
        "/api/v1/newton": {"404", "413", "422"},
    }
    for path, statuses in expected.items():
        responses = document["paths"][path]["post"]["responses"]
        assert statuses <= set(responses), path
        for status in statuses:
            assert responses[status]["content"]["application/json"]["schema"] == ref, (path, status)


# --- the output rate is bounded by samples ------------------------------------------------------


def test_a_hundred_samples_over_a_millisecond_of_a_stiff_spring(client):
    body = {
        "scene_id": "spring_mass_damper",
        "parameters": {"k": 1e6},
        "t_end": 1e-3,
        "fps": 1e5,
        "method": "Radau",
        "check_sensitivity": False,
    }
    response = client.post("/api/v1/simulate", json=body)
    assert response.status_code == 200, response.text
    t = response.json()["t"]
    assert len(t) == 101 and t[-1] == pytest.approx(1e-3)
    assert t[1] == pytest.approx(1e-5)


@pytest.mark.parametrize(
    ("t_end", "fps", "ok"),
    [
        (1.0, 241.0, True),
        (0.0, 1e300, True),  # one sample, whatever the rate
        (1.0, MAX_SAMPLES - 1, True),
        (1.0, MAX_SAMPLES, False),
        (1000.0, 1e308, False),  # t_end × fps overflows to inf: refused, not a crash
        (1.0, 0.0, False),
        (1.0, -60.0, False),
    ],
)
def test_fps_is_bounded_by_the_samples_it_makes(client, t_end, fps, ok):
    body = {"scene_id": "simple_pendulum", "t_end": t_end, "fps": fps, "check_sensitivity": False}
    response = client.post("/api/v1/simulate", json=body)
    if ok:
        assert response.status_code == 200, response.text
        assert len(response.json()["t"]) == int(t_end * fps + 1e-9) + 1
    else:
        assert "fps" in [d["field"] for d in response.json()["detail"]]


# --- plain numbers ------------------------------------------------------------------------------


@pytest.mark.parametrize("method", list(METHODS))
def test_every_stat_of_every_method_is_a_plain_python_value(method):
    fixed = METHODS[method].kind == "fixed"
    request = SimulationRequest(t_end=0.5, method=method, dt=0.01 if fixed else None)
    stats = simulate(scene_id="simple_pendulum", request=request)["stats"]

    def plain(value) -> bool:
        if isinstance(value, dict):
            return all(isinstance(k, str) and plain(v) for k, v in value.items())
        return value is None or type(value) in (bool, int, float, str)

    assert plain(stats), {k: type(v) for k, v in stats.items()}
    json.dumps(stats)  # the stdlib encoder refuses numpy scalars


def test_lsoda_answers_200_through_the_api(client):
    body = {"scene_id": "simple_pendulum", "method": "LSODA", "t_end": 2}
    response = client.post("/api/v1/simulate", json=body)
    assert response.status_code == 200, response.text
    stats = response.json()["stats"]
    assert stats["method"] == "LSODA" and stats["steps"] > 0


# --- huge and tiny numbers ----------------------------------------------------------------------


def test_numbers_past_double_precision_are_a_422_naming_the_parameter(client):
    run = client.post(
        "/api/v1/simulate", json={"scene_id": "simple_pendulum", "parameters": {"l": 1e155}}
    )
    problem = one_error(run, 422)
    assert problem["field"] == "parameters.l" and "1e+155" in problem["message"]
    rest = client.post(
        "/api/v1/equilibria", json={"scene_id": "double_pendulum", "parameters": {"m2": 2e265}}
    )
    assert one_error(rest, 422)["field"] == "parameters.m2"


def test_an_implicit_method_whose_jacobian_overflows_is_refused_naming_the_parameter(client):
    """k/m = 2e214: Radau's Newton iteration squares it past double precision in its first
    step. Not a 500, and not a one-sample 'partial' run: a 422 on the mass, saying overflow."""
    body = {
        "scene_id": "coupled_oscillators",
        "method": "Radau",
        "parameters": {"m": 5e-215},
        "t_end": 0.1,
        "check_sensitivity": False,
    }
    response = client.post("/api/v1/simulate", json=body)
    assert response.status_code == 422, response.text
    [error] = response.json()["detail"]
    assert error["field"] == "parameters.m" and "overflows" in error["message"]


def test_a_level_incline_with_dry_friction_lists_its_equilibria_as_undecided(client):
    response = client.post(
        "/api/v1/equilibria", json={"scene_id": "incline_friction", "parameters": {"alpha": 0.0}}
    )
    assert response.status_code == 200, response.text
    result = response.json()
    assert result["equilibria"] and {e["kind"] for e in result["equilibria"]} == {"marginal"}
    assert any("not smooth" in w for w in result["warnings"])


def test_a_run_of_a_few_samples_can_be_checked_for_sensitivity(client):
    body = {"scene_id": "physical_pendulum", "t_end": 0.085, "check_sensitivity": True}
    assert client.post("/api/v1/simulate", json=body).status_code == 200


# --- settings -----------------------------------------------------------------------------------


def test_settings_read_each_variable_and_keep_the_default_for_nonsense():
    env = {
        "LAGRANGE_LAB_CACHE": "~/elsewhere",
        "LAGRANGE_LAB_DERIVE_SECONDS": "5.5",
        "LAGRANGE_LAB_CC": "none",
        "LAGRANGE_LAB_REDIS_URL": "redis://127.0.0.1:6379/0",
        "LAGRANGE_LAB_WORKERS": "0",  # not positive: the default
        "LAGRANGE_LAB_MAX_BODY_BYTES": "lots",  # not a number: the default
        "LAGRANGE_LAB_POOL_WORKERS": "6",
        "LAGRANGE_LAB_TRUST_FORWARDED": "1",
    }
    s = Settings.from_env(env)
    assert s.cache == Path("~/elsewhere").expanduser()
    assert (s.derive_seconds, s.cc, s.redis_url) == (5.5, "none", "redis://127.0.0.1:6379/0")
    assert (s.workers, s.max_body_bytes) == (Settings.workers, Settings.max_body_bytes)
    assert (s.pool_workers, s.per_client, s.trust_forwarded) == (6, 3, True)
    defaults = Settings.from_env({})
    assert defaults.pool_workers >= 2 and defaults.cache_mb == 256
    assert not defaults.trust_forwarded
    assert Settings.from_env({"LAGRANGE_LAB_DERIVE_SECONDS": "inf"}).derive_seconds == 20.0


def test_every_environment_variable_read_anywhere_is_a_setting_and_documented():
    read = set()
    for folder in ("app", "mechanics"):
        for path in (ROOT / folder).rglob("*.py"):
            read |= set(re.findall(r"LAGRANGE_LAB_[A-Z_]+", path.read_text()))
    names = {f"LAGRANGE_LAB_{name.upper()}" for name in Settings.__dataclass_fields__}
    documented = set(
        re.findall(r"`(LAGRANGE_LAB_[A-Z_]+)`", (ROOT / "docs/settings.md").read_text())
    )
    read.discard("LAGRANGE_LAB_")  # the prefix itself, in app/settings.py
    assert read <= names, read - names
    assert names == documented


def test_a_refusal_names_no_python_class(client):
    """pydantic's 'a valid dictionary or instance of SceneSpec' / 'object to extract fields
    from' mean nothing to a course tool: the one error shape says 'a JSON object'."""
    for body in ({"scene": 5}, {"scene": [1, 2]}, {"scene": "pendulum"}):
        r = client.post("/api/v1/derive", json=body)
        assert r.status_code == 422
        [error] = r.json()["detail"]
        assert error == {"field": "scene", "message": "Input should be a JSON object"}
