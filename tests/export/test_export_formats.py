"""The spec as TOML and JSON, and a trajectory as CSV and JSON with its stats.

TOML is checked by reading it back with the standard library's tomllib: the spec must come back
equal, floats exact, for every built-in scene and for a posted spec full of awkward strings. The
trajectory files are checked against POST /api/v1/simulate's answer to the same request, number
for number (the files write every double exactly).
"""

from __future__ import annotations

import csv
import io
import json
import math
import tomllib

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.export_formats import TomlError, spec_toml, toml_string
from mechanics.scenes import load_scene, scene_ids

client = TestClient(app)

AWKWARD = (
    "quotes \" and ' and \"\"\" and ''', backslash \\ and \\n literally, a real\nnewline, "
    "a tab\t, a bell \x07, DEL \x7f, unicode θ̇ ∂L/∂q — 😀, and [[brackets]] = { x = 1 }"
)


@pytest.mark.parametrize("scene_id", scene_ids())
def test_every_builtin_spec_reads_back_equal_from_toml(scene_id):
    r = client.get(f"/api/v1/export/scenes/{scene_id}/spec.toml")
    assert r.status_code == 200
    assert r.headers["content-type"].startswith("application/toml")
    assert f'filename="{scene_id}.toml"' in r.headers["content-disposition"]
    assert tomllib.loads(r.text) == load_scene(scene_id)
    as_json = client.get(f"/api/v1/export/scenes/{scene_id}/spec.json")
    assert json.loads(as_json.text) == load_scene(scene_id)


def awkward_spec() -> dict:
    spec = load_scene("spring_mass_damper")
    spec["title"] = AWKWARD[:400]
    spec["summary"] = "\\input{x} \"quoted\" 'single' \\u0041 not an escape"
    spec["parameters"] = {**spec["parameters"], "tiny": 5e-324, "huge": 1.7976931348623157e308}
    spec["parameters"]["third"] = 1 / 3
    # (a unit must be one the units grammar reads: the awkward quoting is in title and summary)
    spec["units"] = {**spec.get("units", {}), "tiny": "kg*m^2/s^2"}
    return spec


def test_a_posted_spec_with_awkward_strings_reads_back_equal():
    spec = awkward_spec()
    r = client.post("/api/v1/export/spec?format=toml", json={"scene": spec})
    assert r.status_code == 200, r.text
    back = tomllib.loads(r.text)
    assert back["title"] == spec["title"]
    assert back["summary"] == spec["summary"]
    assert back["units"]["tiny"] == "kg*m^2/s^2"
    assert back["parameters"]["tiny"] == 5e-324
    assert back["parameters"]["huge"] == 1.7976931348623157e308
    assert back["parameters"]["third"] == 1 / 3
    as_json = client.post("/api/v1/export/spec?format=json", json={"scene": spec})
    assert back == json.loads(as_json.text)
    # and the TOML is a spec the API derives as it is
    assert client.post("/api/v1/derive", json={"scene": back}).status_code == 200


def test_toml_strings_escape_what_toml_requires():
    # expectations written from the TOML 1.0 spec's list of escapes, not from the code
    assert toml_string('a"b') == '"a\\"b"'
    assert toml_string("a\\b") == '"a\\\\b"'
    assert toml_string("a\nb\tc") == '"a\\nb\\tc"'
    assert toml_string("\x00\x1f\x7f") == '"\\u0000\\u001F\\u007F"'
    assert toml_string("θ😀") == '"θ😀"'
    for text in (AWKWARD, "", "'''", '"""', "\\", "\r\n"):
        assert tomllib.loads(f"x = {toml_string(text)}")["x"] == text


def test_toml_values_round_trip_exactly():
    document = {
        "floats": [0.1, 1e-300, -2.5e300, 1 / 3, -0.0, 1e16, 123456789.123456789],
        "ints": [0, -7, 2**53],
        "flags": [True, False],
        "nested": {"a b": {"c": [[1, 2], ["x", "y"]]}, "ok-key": "v"},
        "special": {"inf": math.inf},
        "items": [{"name": "one", "at": {"frame": "N", "components": [1, "x"]}}],
    }
    assert tomllib.loads(spec_toml(document)) == document
    with pytest.raises(TomlError):
        spec_toml({"x": [1, None]})


def test_trajectory_csv_matches_the_simulation_number_for_number():
    body = {
        "scene_id": "spring_mass_damper",
        "t_end": 2,
        "fps": 20,
        "parameters": {"k": 3.0},
        "check_sensitivity": False,
    }
    run = client.post("/api/v1/simulate", json=body).json()
    r = client.post("/api/v1/export/trajectory?format=csv", json=body)
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].startswith("text/csv")
    lines = r.text.splitlines()
    comments = [line for line in lines if line.startswith("#")]
    assert any(line == f"# stats.steps: {run['stats']['steps']}" for line in comments)
    assert any(line.startswith("# parameters: ") and '"k": 3.0' in line for line in comments)
    rows = list(csv.reader(io.StringIO("\n".join(x for x in lines if not x.startswith("#")))))
    header, data = rows[0], rows[1:]
    (q,) = run["q"]
    unit = load_scene("spring_mass_damper")["units"][q]
    assert header[:3] == ["t [s]", f"{q} [{unit}]", f"{q}_dot [{unit}/s]"]
    assert header[3:] == ["T [J]", "V [J]", "E [J]", "W_nc [J]", "W_drive [J]"]
    assert len(data) == len(run["t"]) == 41
    columns = list(zip(*data, strict=True))
    assert [float(v) for v in columns[0]] == run["t"]
    assert [float(v) for v in columns[1]] == run["q"][q]
    assert [float(v) for v in columns[2]] == run["q_dot"][q]
    assert [float(v) for v in columns[5]] == run["energy"]["E"]


@pytest.mark.slow
@pytest.mark.parametrize("scene_id", scene_ids())
def test_every_builtin_scenes_trajectory_csv_has_every_sample_and_column(scene_id):
    query = "t_end=0.5&method=DOP853"
    r = client.get(f"/api/v1/export/scenes/{scene_id}/trajectory.csv?{query}")
    assert r.status_code == 200, r.text
    rows = [line.split(",") for line in r.text.splitlines() if not line.startswith("#")]
    coordinates = load_scene(scene_id)["coordinates"]
    assert len(rows[0]) == 1 + 2 * len(coordinates) + 5
    run = client.post(
        "/api/v1/simulate", json={"scene_id": scene_id, "t_end": 0.5, "method": "DOP853"}
    ).json()
    assert len(rows) - 1 == len(run["t"])
    for i, q in enumerate(coordinates):
        assert rows[0][1 + i].split(" ")[0] == q
        assert [float(row[1 + i]) for row in rows[1:]] == run["q"][q]


def test_trajectory_json_of_a_posted_spec_carries_stats_and_units():
    spec = load_scene("simple_pendulum")
    spec["title"] = "My pendulum"
    body = {"scene": spec, "t_end": 1, "method": "rk4", "dt": 0.01, "check_sensitivity": False}
    run = client.post("/api/v1/simulate", json=body).json()
    r = client.post("/api/v1/export/trajectory?format=json", json=body)
    assert r.status_code == 200, r.text
    doc = r.json()
    assert doc["t"] == run["t"] and doc["q"] == run["q"] and doc["energy"] == run["energy"]
    # rk4 takes exactly dt = 0.01: t_end / dt = 100 steps, the step stated in the stats
    assert doc["stats"]["method"] == "rk4" and doc["stats"]["steps"] == 100
    assert doc["stats"]["dt"] == 0.01
    assert {"name": "theta", "unit": spec["units"]["theta"]} in doc["columns"]
    assert doc["request"]["dt"] == 0.01 and doc["request"]["scene"] == "My pendulum"


def test_trajectory_get_uses_the_page_query_and_refuses_bad_values():
    r = client.get("/api/v1/export/scenes/simple_pendulum/trajectory.csv?t_end=0.5&l=2")
    assert r.status_code == 200
    assert "# parameters: " in r.text and '"l": 2.0' in r.text
    r = client.get("/api/v1/export/scenes/simple_pendulum/trajectory.json?t_end=5000")
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "t_end"
    r = client.get("/api/v1/export/scenes/simple_pendulum/trajectory.xml")
    assert r.status_code == 422
    r = client.get("/api/v1/export/scenes/nope/trajectory.csv")
    assert r.status_code == 404 and r.json()["detail"][0]["field"] == "scene_id"
