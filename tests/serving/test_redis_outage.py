"""A hung Redis costs a request a fraction of a second, not the class half a minute (issue 24,
item 3).

Found by an attacker-and-class review: a Redis that is stopped (SIGSTOP: it accepts connections
and never answers) froze every request for ~30 s, because each operation waited its 5 s socket
timeout, redis-py retried it with back-off, and a request makes several; docs/deploy.md promised
"at most a second". Here a real redis-server is stopped with SIGSTOP under a real uvicorn server
and under threads of this process; each request must answer within a second of what the same
work costs with Redis up, the outage is logged once per process, and after SIGCONT the cache
shares through Redis again.
"""

from __future__ import annotations

import concurrent.futures
import json
import logging
import os
import signal
import subprocess
import sys
import threading
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from servers import free_port, serving
from test_redis import redis, start_redis, stop

from mechanics import cache

ROOT = Path(__file__).resolve().parents[2]


@contextmanager
def hung(proc: subprocess.Popen) -> Iterator[None]:
    """Redis stopped, not dead: its socket accepts and never answers. Continued afterwards."""
    os.kill(proc.pid, signal.SIGSTOP)
    try:
        yield
    finally:
        os.kill(proc.pid, signal.SIGCONT)


@pytest.fixture
def own_redis(tmp_path: Path) -> Iterator[tuple[subprocess.Popen, str]]:
    proc, url = start_redis(tmp_path)
    yield proc, url
    os.kill(proc.pid, signal.SIGCONT)
    stop(proc)


def test_threads_meet_a_hung_redis_once_and_share_again_after_it(
    own_redis, tmp_path, monkeypatch, caplog
):
    """Eight requests at once while Redis is stopped: all answer within a second, one warning;
    after SIGCONT a background probe closes the breaker and entries reach Redis again."""
    proc, url = own_redis
    monkeypatch.setenv(cache.REDIS_ENV_VAR, url)
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path / "disk"))
    monkeypatch.setitem(cache._redis_state, "down_until", 0.0)
    monkeypatch.setitem(cache._redis_state, "logged", False)
    monkeypatch.setitem(cache._redis_state, "probing", False)
    monkeypatch.setattr(cache.cache_redis, "RETRY_SECONDS", 0.5)
    client = redis.Redis.from_url(url)
    run = time.time()
    assert cache.get_or_compute("newton", {"up": run}, lambda: {"n": 0}) == {"n": 0}
    assert cache.flush()

    def request(i: int) -> float:
        start = time.monotonic()
        assert cache.get_or_compute("newton", {"hung": run, "i": i}, lambda: {"n": i}) == {"n": i}
        return time.monotonic() - start

    with caplog.at_level(logging.WARNING, logger="mechanics.cache"), hung(proc):
        with concurrent.futures.ThreadPoolExecutor(8) as pool:
            seconds = list(pool.map(request, range(8)))
        seconds += [request(i) for i in range(8, 12)]  # and the ones after them
    assert max(seconds) < 1.0, seconds
    assert len([r for r in caplog.records if "Redis is unreachable" in r.message]) == 1

    deadline = time.monotonic() + 10
    while True:  # the probe runs in the background once RETRY_SECONDS have passed
        cache.get_or_compute("newton", {"after": run, "t": time.monotonic()}, dict)
        if not cache._redis_state["logged"]:
            break
        assert time.monotonic() < deadline, "the breaker never closed after SIGCONT"
        time.sleep(0.1)
    assert cache.get_or_compute("newton", {"back": run}, lambda: {"n": "back"}) == {"n": "back"}
    assert cache.flush()
    assert client.exists(f"{cache.REDIS_PREFIX}newton:{cache.key_for('newton', {'back': run})}")


def post(url: str, path: str, body: dict) -> tuple[int, dict, float]:
    request = urllib.request.Request(
        f"{url}{path}", data=json.dumps(body).encode(), headers={"content-type": "application/json"}
    )
    start = time.monotonic()
    with urllib.request.urlopen(request, timeout=120) as answer:
        return answer.status, json.loads(answer.read()), time.monotonic() - start


def equilibria(url: str, omega: float) -> tuple[int, dict, float]:
    return post(
        url, "/api/v1/equilibria", {"scene_id": "bead_on_hoop", "parameters": {"Omega": omega}}
    )


def test_a_server_answers_within_a_second_while_redis_is_stopped(own_redis, tmp_path):
    """Equilibria at values nobody asked for (a cache miss: Redis is read, locked and written)
    cost what they cost with Redis up, plus at most a second; after SIGCONT they are shared."""
    proc, redis_url = own_redis
    client = redis.Redis.from_url(redis_url)
    port = free_port()
    env = os.environ | {
        cache.REDIS_ENV_VAR: redis_url,
        cache.ENV_VAR: str(tmp_path / "disk"),
        "LAGRANGE_LAB_POOL_WORKERS": "1",
        "LAGRANGE_LAB_WARM": "0",
    }
    command = [sys.executable, "-m", "uvicorn", "app.main:app", "--port", str(port)]
    command += ["--host", "127.0.0.1", "--log-level", "warning"]
    log: list[str] = []
    with serving(command, port, cwd=ROOT, env=env, stderr=subprocess.PIPE, text=True) as (
        url,
        server,
    ):
        threading.Thread(target=lambda: log.extend(server.stderr), daemon=True).start()
        assert equilibria(url, 6.0)[0] == 200  # derives the scene once (every value reuses it)
        up = max(equilibria(url, omega)[2] for omega in (6.5, 7.0))
        with hung(proc):
            stopped = []
            for omega in (7.5, 8.0, 8.5, 9.0):
                status, body, seconds = equilibria(url, omega)
                assert status == 200 and body["equilibria"]
                stopped.append(seconds)
        assert max(stopped) < up + 1.0, (up, stopped)
        shared = client.keys(f"{cache.REDIS_PREFIX}equilibria:*")
        deadline = time.monotonic() + 30  # the breaker probes Redis every 10 s
        omega = 10.0
        while set(client.keys(f"{cache.REDIS_PREFIX}equilibria:*")) == set(shared):
            assert time.monotonic() < deadline, "the server never shared through Redis again"
            omega += 0.25
            assert equilibria(url, omega)[0] == 200
            time.sleep(0.5)
    assert "".join(log).count("Redis is unreachable") <= 2  # the server and its pool worker
