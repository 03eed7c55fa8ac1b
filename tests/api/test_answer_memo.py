"""Identical built-in runs are computed once (app/memo.py); only load-free answers are shared."""

from __future__ import annotations

import asyncio
from concurrent.futures import ThreadPoolExecutor

import orjson
import pytest
from fastapi.testclient import TestClient

from app.main import app
from app.memo import AnswerMemo
from app.routes import simulate as simulate_route


def run_async(coroutine_function):
    """asyncio.run in a thread of its own: the browser tests' Playwright (sync API) keeps an
    event loop running in the main thread for the whole session."""
    with ThreadPoolExecutor(1) as pool:
        return pool.submit(asyncio.run, coroutine_function()).result()


def test_concurrent_identical_requests_share_one_computation():
    calls = 0

    async def compute():
        nonlocal calls
        calls += 1
        await asyncio.sleep(0.05)
        return b"answer", True

    async def crowd():
        memo = AnswerMemo()
        bodies = await asyncio.gather(*(memo.get_or_compute("k", compute) for _ in range(20)))
        again = await memo.get_or_compute("k", compute)
        return bodies, again

    bodies, again = run_async(crowd)
    assert bodies == [b"answer"] * 20 and again == b"answer"
    assert calls == 1


def test_an_answer_not_to_keep_and_a_failure_are_each_waiters_own():
    calls = 0

    async def busy():
        nonlocal calls
        calls += 1
        mine = calls
        await asyncio.sleep(0.02)
        return f"cut short {mine}".encode(), False

    async def failing():
        raise RuntimeError("no slot")

    async def run():
        memo = AnswerMemo()
        first = await asyncio.gather(*(memo.get_or_compute("k", busy) for _ in range(3)))
        with pytest.raises(RuntimeError):
            await memo.get_or_compute("f", failing)
        return first, memo.get("k"), memo.get("f")

    first, kept, failed = run_async(run)
    assert calls == 3  # nobody was handed another request's cut-short run
    assert sorted(first) == [b"cut short 1", b"cut short 2", b"cut short 3"]
    assert kept is None and failed is None


def test_the_memo_is_bounded_by_count_and_bytes():
    memo = AnswerMemo(max_entries=3, max_bytes=1000)
    for i in range(5):
        memo.put(f"k{i}", b"x" * 100)
    assert [memo.get(f"k{i}") is not None for i in range(5)] == [False, False, True, True, True]
    memo.put("big", b"x" * 600)  # over an eighth of the bytes: not kept at all
    assert memo.get("big") is None
    wide = AnswerMemo(max_entries=100, max_bytes=1000)
    for i in range(12):
        wide.put(f"m{i}", b"x" * 100)  # ten of them fill the bytes
    assert [wide.get(f"m{i}") is not None for i in range(12)] == [False] * 2 + [True] * 10


def test_a_built_in_run_asked_twice_is_the_same_answer_computed_once():
    body = {"scene_id": "simple_pendulum", "parameters": {"l": 1.37}, "t_end": 2, "fps": 30}
    with TestClient(app) as client:
        before = simulate_route.built_in_runs.misses
        first = client.post("/api/v1/simulate", json=body)
        # the same request with its keys in another order is the same request
        second = client.post("/api/v1/simulate", json=dict(reversed(list(body.items()))))
    assert first.status_code == second.status_code == 200
    assert first.content == second.content
    assert simulate_route.built_in_runs.misses == before + 1
    assert len(orjson.loads(first.content)["t"]) == 61


def test_a_run_near_its_wall_time_is_not_shared():
    quick = {"stats": {"wall_time": 0.01}, "warnings": []}
    slow = {"stats": {"wall_time": 9.9}, "warnings": []}
    cut = {
        "stats": {"wall_time": 0.01},
        "warnings": ["The run took longer than its 10 s of wall time (the server may be busy)"],
    }
    assert simulate_route._not_load_dependent(quick)
    assert not simulate_route._not_load_dependent(slow)
    assert not simulate_route._not_load_dependent(cut)


def test_an_answer_asked_again_is_sent_gzipped_once_compressed():
    import gzip

    body = {"scene_id": "spring_mass_damper", "parameters": {"k": 7.5}, "t_end": 3, "fps": 30}
    with TestClient(app) as client:
        first = client.post("/api/v1/simulate", json=body)
        again = client.post("/api/v1/simulate", json=body, headers={"accept-encoding": "gzip"})
    assert again.headers["content-encoding"] == "gzip"
    assert again.content == first.content  # httpx decodes it: the same answer
    memo = simulate_route.built_in_runs
    key = next(k for k in memo._answers if '"k":7.5' in k)
    assert gzip.decompress(memo.gzipped(key, memo.get(key))) == first.content
    # another answer under the same key is compressed as itself, never given the kept twin
    assert gzip.decompress(memo.gzipped(key, b'{"other":1}')) == b'{"other":1}'
