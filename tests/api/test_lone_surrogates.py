"""A lone UTF-16 surrogate in a JSON body is a 422 naming its field on every route (issue 24,
item 6: ``{"parameters": {"\\ud800": 1}}`` was a 500 on /simulate, /equilibria, /precision and
the script and trajectory exports, because such a string cannot be written as UTF-8)."""

from __future__ import annotations

import json

import pytest
from fastapi.testclient import TestClient

from app.errors import lone_surrogate_at
from app.main import app

client = TestClient(app, raise_server_exceptions=False)

POSTS = sorted(p for p, ops in app.openapi()["paths"].items() if "post" in ops)
BODIES = {
    "parameters.\\ud800": '{"scene_id": "simple_pendulum", "parameters": {"\\ud800": 1}}',
    "initial.\\udfff": '{"scene_id": "simple_pendulum", "initial": {"\\udfff": 1}}',
    "answer": '{"scene_id": "simple_pendulum", "answer": "x\\uDC00y"}',
    "bodies[0].name": '{"scene": {"bodies": [{"name": "b\\ud800"}]}}',
}


def test_every_post_route_is_tried():
    assert len(POSTS) >= 12 and "/api/v1/simulate" in POSTS


@pytest.mark.parametrize("field", BODIES)
@pytest.mark.parametrize("path", POSTS)
def test_a_lone_surrogate_is_a_422_naming_its_field(path, field):
    r = client.post(path, content=BODIES[field], headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    (problem,) = r.json()["detail"]
    assert problem["field"] == field
    assert "surrogate" in problem["message"]


def test_a_whole_surrogate_pair_is_a_character_and_passes():
    # U+1F600 written as its pair: JSON decodes the two escapes to one character
    assert lone_surrogate_at(json.loads('{"title": ["\\ud83d\\ude00"]}')) is None
    assert lone_surrogate_at({"a": [1, {"b": "\ud83d"}]}) == (["a", 1, "b"], "\\ud83d")


def test_a_deeply_nested_document_is_walked_without_recursion():
    document: object = "\udc00"
    for _ in range(5000):
        document = [document]
    path, code = lone_surrogate_at(document)
    assert len(path) == 5000 and code == "\\udc00"


def test_a_query_with_surrogate_bytes_is_no_500():
    r = client.get("/api/v1/export/scenes/simple_pendulum/trajectory.csv?%ED%A0%80=1")
    assert r.status_code < 500, r.text
