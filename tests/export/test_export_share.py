"""Share links: the page's state compressed into the URL, restored exactly, and a link someone
else made refused with a 422 naming what is wrong, never a 500 and never unbounded work."""

from __future__ import annotations

import base64
import json
import random
import zlib
from urllib.parse import parse_qsl, urlsplit

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.export_share import MAX_JSON, MAX_TOKEN, ShareError, decode_state, encode_state
from mechanics.scenes import load_scene

client = TestClient(app)

#: Doubles that a decimal round trip with too few digits would change.
AWKWARD_FLOATS = {
    "m1": 0.1 + 0.2,
    "m2": 1 / 3,
    "l1": 1 + 2**-52,
    "l2": 0.7 + 0.1,
    "g": 9.810000000000002,
}


def token_of(document: object) -> str:
    """A token made by hand (the format: 'z' + base64url of zlib of JSON), for hostile ones."""
    raw = zlib.compress(
        json.dumps(document).encode() if not isinstance(document, bytes) else document
    )
    return "z" + base64.urlsafe_b64encode(raw).decode().rstrip("=")


def test_a_builtin_scenes_state_round_trips_exactly():
    state = {
        "scene_id": "double_pendulum",
        "parameters": AWKWARD_FLOATS,
        "initial": {"theta1": 2.0943951023931953, "theta2_dot": -1e-300},
        "method": "rk4",
        "dt": 0.005,
        "t_end": 17.25,
        "compare": True,
        "method_b": "euler",
        "lecture": True,
        "lecture_step": 5,
        "phase": "theta2",
    }
    r = client.post("/api/v1/export/share", json=state)
    assert r.status_code == 200, r.text
    link = r.json()
    assert link["url"] == f"/s/{link['token']}"
    back = client.get(link["api"])
    assert back.status_code == 200
    assert back.json() == state  # every float bit for bit: == on doubles
    # the link opens the scene's page with the page's own query keys, numbers exact
    opened = client.get(link["url"], follow_redirects=False)
    assert opened.status_code == 303
    where = urlsplit(opened.headers["location"])
    assert where.path == "/scenes/double_pendulum"
    query = dict(parse_qsl(where.query))
    for name, value in AWKWARD_FLOATS.items():
        assert float(query[name]) == value
    assert float(query["theta1"]) == 2.0943951023931953
    assert (query["method"], float(query["dt"]), float(query["t_end"])) == ("rk4", 0.005, 17.25)
    assert (query["lecture"], query["step"], query["compare"], query["method_b"]) == (
        "1",
        "6",  # lecture_step 5 (from 0) is the page's step=6 (from 1, as its header counts)
        "1",
        "euler",
    )
    assert query["phase"] == "theta2"


def test_a_posted_spec_round_trips_exactly_and_opens_the_editor():
    spec = load_scene("elastic_pendulum")
    spec["title"] = 'Custom "spring" \\ pendulum θ — 😀'
    spec["parameters"] = {**spec["parameters"], "k": 0.1 + 0.7}
    state = {"scene": spec, "initial": {"r": 1.25}, "method": "DOP853", "rtol": 1e-11}
    state["atol"] = 3e-12
    r = client.post("/api/v1/export/share", json=state)
    assert r.status_code == 200, r.text
    link = r.json()
    back = client.get(link["api"]).json()
    assert back["scene"]["title"] == spec["title"]
    assert back["scene"]["parameters"] == spec["parameters"]
    assert back["initial"] == {"r": 1.25} and (back["rtol"], back["atol"]) == (1e-11, 3e-12)
    # the spec derives to the same equations as the original
    assert (
        client.post("/api/v1/derive", json={"scene": back["scene"]}).json()["equations"]
        == (client.post("/api/v1/derive", json={"scene": spec}).json()["equations"])
    )
    opened = client.get(link["url"], follow_redirects=False)
    assert opened.status_code == 303
    assert opened.headers["location"] == f"/editor?share={link['token']}"


def test_encode_decode_is_exact_and_bounded():
    state = {"parameters": AWKWARD_FLOATS, "text": 'θ\n"\\', "n": [1, 2.5, -0.0]}
    assert decode_state(encode_state(state)) == state
    with pytest.raises(ShareError, match="characters"):
        noise = random.Random(0).randbytes(12_000)  # incompressible: ~16 kB of base64
        encode_state({"noise": base64.b64encode(noise).decode()})


@pytest.mark.parametrize(
    "token, says",
    [
        ("", "not a share token"),
        ("hello", "not a share token"),
        ("z!!!", "not a share token"),
        ("z" + "A" * (MAX_TOKEN + 1), "at most"),
        ("zAAAA", "damaged"),
        (token_of({"scene_id": "simple_pendulum"})[:-6], "cut short"),
        (token_of(b"\xff\xfe not json"), "not valid JSON"),
        (token_of(b'{"scene_id": "simple_pendulum", "t_end": NaN}'), "NaN"),
        (token_of([1, 2]), "not a JSON object"),
        (token_of(b" " * (4 * MAX_JSON)), "larger than"),  # a zlib bomb stops at the limit
    ],
)
def test_a_damaged_or_hostile_token_is_a_422_on_token(token, says):
    r = client.get(f"/api/v1/export/share/{token}" if token else "/api/v1/export/share/%20")
    assert r.status_code == 422, r.text
    (problem,) = r.json()["detail"]
    assert problem["field"] == "token"
    assert says in problem["message"]


@pytest.mark.parametrize(
    "state, field",
    [
        ({"scene_id": "simple_pendulum", "t_end": 5000}, "token.t_end"),
        ({"scene_id": "simple_pendulum", "parameters": {"m": "heavy"}}, "token.parameters.m"),
        ({"scene_id": "simple_pendulum", "method": "warp"}, "token.method"),
        ({"scene_id": "simple_pendulum", "lecture_step": -1}, "token.lecture_step"),
        ({"scene_id": "simple_pendulum", "owner": "me"}, "token.owner"),
        ({"scene_id": "Simple Pendulum!"}, "token.scene_id"),
        ({"scene": {"title": "no bodies"}}, "token.scene.coordinates"),
    ],
)
def test_a_token_whose_state_breaks_the_schema_names_the_field(state, field):
    token = token_of(state)
    for url in (f"/api/v1/export/share/{token}", f"/s/{token}"):
        r = client.get(url, follow_redirects=False)
        assert r.status_code == 422, r.text
        assert field in {p["field"] for p in r.json()["detail"]}


def test_posting_a_state_checks_it_like_any_request():
    r = client.post("/api/v1/export/share", json={"scene_id": "simple_pendulum", "t_end": -1})
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "t_end"
    r = client.post(
        "/api/v1/export/share",
        content=b'{"scene_id": "simple_pendulum", "parameters": {"m": NaN}}',
        headers={"content-type": "application/json"},
    )
    assert r.status_code == 422
    r = client.post("/api/v1/export/share", json={"parameters": {}})
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "scene_id"


def test_a_token_with_bytes_after_its_state_is_refused():
    """Hostile play-test (2026-12-02): bytes after the compressed state were ignored, so
    'token' + 'AAAA', 'AAAB', ... opened the same state under ever new keys of the links' memo."""
    token = encode_state({"scene_id": "simple_pendulum"})
    assert decode_state(token) == {"scene_id": "simple_pendulum"}
    with pytest.raises(ShareError, match="goes on after"):
        decode_state(token + "AAAA")
    r = TestClient(app).get(f"/api/v1/export/share/{token}AAAA")
    assert r.status_code == 422
    assert r.json()["detail"][0]["field"] == "token"
