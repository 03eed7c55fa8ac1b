"""An error answer stays small whatever was sent (issue 24, item 6: 439 kB of
``positive_coordinates`` produced a 2.3 MB error; ``units`` had no bound either)."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from app.errors import MAX_PROBLEMS, bounded_detail
from app.main import app
from mechanics.scenes import load_scene
from mechanics.spec import MAX_COORDINATES, MAX_PARAMETERS

client = TestClient(app)


def _scene(**changes):
    return {**load_scene("simple_pendulum"), **changes}


@pytest.mark.parametrize(
    "field, value",
    [
        ("positive_coordinates", ["1bad"] * 40_000),
        ("positive_coordinates", ["theta"] * (MAX_COORDINATES + 1)),
        ("units", {f"p{i}": "m" for i in range(40_000)}),
        ("units", {f"x{i}": "1" for i in range(MAX_PARAMETERS + MAX_COORDINATES + 1)}),
    ],
)
def test_an_oversized_list_is_one_small_422_naming_it(field, value):
    r = client.post("/api/v1/derive", json={"scene": _scene(**{field: value})})
    assert r.status_code == 422, r.text[:300]
    assert len(r.content) < 2_000
    assert [p["field"] for p in r.json()["detail"]] == [field]


def test_the_limits_leave_room_for_every_honest_unit():
    scene = _scene(units={"theta": "rad", "m": "kg", "l": "m", "g": "m/s^2"})
    scene["positive_coordinates"] = []
    assert client.post("/api/v1/derive", json={"scene": scene}).status_code == 200


def test_many_problems_are_listed_up_to_a_bound_and_counted():
    detail = [{"field": f"f{i}", "message": "x" * 5000} for i in range(1000)]
    out = bounded_detail(detail)
    assert len(out) == MAX_PROBLEMS + 1
    assert out[-1] == {
        "field": "body",
        "message": f"and {1000 - MAX_PROBLEMS} more problems, not listed",
    }
    assert sum(len(d["message"]) for d in out) < 40_000


def test_a_body_of_many_bad_items_answers_a_bounded_error():
    # every item of a list of bodies is bad: bounded by the list's own size limit, and by the count
    scene = _scene(bodies=[{"name": f"b{i}", "mass": "1bad$"} for i in range(8)])
    scene["forces"] = [{"point": "nowhere", "components": ["$", "$"]} for _ in range(16)]
    r = client.post("/api/v1/derive", json={"scene": scene})
    assert r.status_code == 422
    assert len(r.json()["detail"]) <= MAX_PROBLEMS + 1
