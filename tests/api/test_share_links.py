"""Opening a share link costs the server once per link, within a budget that grows with the
link's size, counted against whoever opens it (issue 24, item 5: one GET of a 185-character link
with a posted spec cost 20 s of a pool worker and was never kept; four visitors made honest
answer checks fail, and any page could trigger it with an <img>)."""

from __future__ import annotations

import asyncio
import threading
import time

import httpx
import pytest
from fastapi.testclient import TestClient

from app import derivations, share_links
from app.main import app
from mechanics.budget import BudgetExceeded
from mechanics.scenes import load_scene

client = TestClient(app)


@pytest.fixture
def pool_calls(monkeypatch):
    """Every pool job the routes start, with its budget and client, still run for real."""
    calls: list[dict] = []
    real = derivations.in_pool

    def recorded(http, job, *args, **kwargs):
        calls.append({"job": job.__name__, "seconds": kwargs.get("seconds"), "client": http.client})
        return real(http, job, *args, **kwargs)

    monkeypatch.setattr(derivations, "in_pool", recorded)
    share_links.memo.clear()
    return calls


def _posted_link() -> str:
    scene = load_scene("simple_pendulum")
    scene["title"] = f"a posted pendulum {time.time_ns()}"  # a link no earlier test opened
    r = client.post("/api/v1/export/share", json={"scene": scene, "initial": {"theta": 0.3}})
    assert r.status_code == 200, r.text
    return r.json()["token"]


def test_a_link_opened_again_is_not_checked_again(pool_calls):
    token = _posted_link()
    pool_calls.clear()  # making the link checked it once, as the one who made it
    for _ in range(3):
        assert client.get(f"/api/v1/export/share/{token}").status_code == 200
        r = client.get(f"/s/{token}", follow_redirects=False)
        assert r.status_code == 303
    assert [c["job"] for c in pool_calls] == ["run_problems"]


def test_a_short_links_check_gets_seconds_not_the_posted_scenes_twenty(pool_calls):
    token = _posted_link()
    pool_calls.clear()
    client.get(f"/api/v1/export/share/{token}")
    (call,) = pool_calls
    assert len(token) < 1000
    assert call["seconds"] is not None and call["seconds"] < 6  # it was 20 s (the default)
    assert call["client"] is not None  # counted against the visitor's address


def test_a_long_link_never_gets_more_than_a_posted_scene():
    assert share_links.link_seconds("z" * 12_000, ceiling=20.0) == 20.0
    assert share_links.link_seconds("z" * 185, ceiling=20.0) < 3


def test_a_check_past_its_budget_opens_the_link_unchecked_once(monkeypatch):
    share_links.memo.clear()
    token = _posted_link()
    calls = []

    def too_slow(http, job, *args, **kwargs):
        calls.append(kwargs.get("seconds"))
        raise BudgetExceeded("time", f"past {kwargs.get('seconds')} s")

    monkeypatch.setattr(derivations, "in_pool", too_slow)
    for _ in range(3):
        r = client.get(f"/api/v1/export/share/{token}")
        assert r.status_code == 200  # cannot decide: the page's own run will say
        assert r.json()["initial"] == {"theta": 0.3}
    assert len(calls) == 1


def test_a_refused_link_is_refused_again_without_work(pool_calls):
    token = _posted_link()
    share_links.memo.clear()
    pool_calls.clear()
    bad = token[:-4] + "AAAA"  # damaged in transit
    answers = [client.get(f"/api/v1/export/share/{bad}") for _ in range(3)]
    assert {a.status_code for a in answers} == {422}
    assert len({a.text for a in answers}) == 1
    assert len(pool_calls) <= 1


def test_visitors_opening_a_link_at_once_share_one_check(monkeypatch):
    share_links.memo.clear()
    token = _posted_link()
    running = threading.Semaphore(0)
    calls = []

    def slow(http, job, *args, **kwargs):
        calls.append(1)
        running.release()
        time.sleep(0.5)
        return []

    monkeypatch.setattr(derivations, "in_pool", slow)

    async def visit_four() -> list[int]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as c:
            answers = await asyncio.gather(
                *(c.get(f"/api/v1/export/share/{token}") for _ in range(4))
            )
        return [a.status_code for a in answers]

    assert asyncio.run(visit_four()) == [200] * 4
    assert len(calls) == 1
