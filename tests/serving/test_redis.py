"""The cache shared through a real Redis (Debian's redis-server, started here on a free loopback
port in a temporary folder): entries with TTLs, verified on read, single flight across processes
with separate disks, locks that expire, Redis going away; and two real app servers (uvicorn
processes of app.main:app) sharing one Redis: a derivation computed by one is served by the other
without being computed again, and concurrent identical requests to both cost one computation.

Computations are counted by Redis itself (``lagrange-lab:computed:<store>``, incremented by every
server that computes a value: `mechanics.cache.shared_computations`).
"""

from __future__ import annotations

import concurrent.futures
import json
import logging
import os
import shutil
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
from servers import free_port

from mechanics import cache

ROOT = Path(__file__).resolve().parents[2]
REDIS_SERVER = shutil.which("redis-server")
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")

if REDIS_SERVER is None and not IN_CI:  # CI installs it (.ci/run) and fails without it
    pytest.skip(
        "Debian's redis-server is not installed (apt-get install redis-server)",
        allow_module_level=True,
    )

redis = pytest.importorskip("redis") if not IN_CI else __import__("redis")


def start_redis(folder: Path) -> tuple[subprocess.Popen, str]:
    """redis-server on a free loopback port, nothing persisted, its files in ``folder``."""
    if REDIS_SERVER is None:
        pytest.fail("redis-server is missing under CI: .ci/run should have installed it")
    port = free_port()
    proc = subprocess.Popen(
        [REDIS_SERVER, "--port", str(port), "--bind", "127.0.0.1", "--dir", str(folder)]
        + ["--save", "", "--appendonly", "no", "--protected-mode", "yes"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    url = f"redis://127.0.0.1:{port}/0"
    client = redis.Redis.from_url(url)
    deadline = time.monotonic() + 20
    while True:
        try:
            client.ping()
            return proc, url
        except redis.ConnectionError:
            if time.monotonic() > deadline or proc.poll() is not None:
                proc.kill()
                pytest.fail("redis-server did not start")
            time.sleep(0.05)


def stop(proc: subprocess.Popen) -> None:
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


@pytest.fixture(scope="module")
def redis_url(tmp_path_factory) -> Iterator[str]:
    proc, url = start_redis(tmp_path_factory.mktemp("redis"))
    yield url
    stop(proc)


@pytest.fixture
def client(redis_url: str):
    return redis.Redis.from_url(redis_url)


@pytest.fixture
def shared(redis_url: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """This process caches through the Redis server (its disk a fresh folder)."""
    monkeypatch.setenv(cache.REDIS_ENV_VAR, redis_url)
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path / "disk"))
    monkeypatch.setitem(cache._redis_state, "down_until", 0.0)
    monkeypatch.setitem(cache._redis_state, "logged", False)
    monkeypatch.setitem(cache._disk_state, "down_until", 0.0)
    return redis_url


def rkey(store: str, parts: object, suffix: str = "") -> str:
    return f"{cache.REDIS_PREFIX}{store}:{cache.key_for(store, parts)}" + suffix


# --- the cache through Redis ------------------------------------------------------------------


def test_an_entry_lives_in_redis_with_its_store_ttl_not_on_disk(shared, client, tmp_path):
    parts = {"spec": "ttl", "n": time.time()}
    assert cache.get_or_compute("equilibria", parts, lambda: {"x": 1}) == {"x": 1}
    assert cache.flush()  # writes leave the request's path: a background thread does them
    ttl = client.pttl(rkey("equilibria", parts))
    assert 0 < ttl <= cache.STORES["equilibria"].ttl_seconds * 1000
    assert client.exists(rkey("equilibria", parts, ":lock")) == 0  # released
    assert not (tmp_path / "disk").exists()


def test_a_tampered_redis_entry_is_recomputed_never_served(shared, client):
    parts = {"spec": "tampered", "n": time.time()}
    cache.get_or_compute("newton", parts, lambda: {"tension": "good"})
    assert cache.flush()
    key = rkey("newton", parts)
    client.set(key, client.get(key)[:-3])  # truncated
    cache._memories.clear()
    assert cache.get_or_compute("newton", parts, lambda: {"tension": "again"}) == {
        "tension": "again"
    }
    assert cache.flush()
    cache._memories.clear()
    assert cache.get("newton", parts) == {"tension": "again"}


WORKER = """
import json, os, sys, time
from mechanics import cache
parts = json.loads(sys.argv[1])
def compute():
    time.sleep(1.0)
    return {"by": os.getpid()}
print(json.dumps(cache.get_or_compute("equilibria", parts, compute)))
"""


def test_processes_with_separate_disks_share_one_computation(shared, tmp_path):
    parts = {"spec": "flight", "n": time.time()}
    before = cache.shared_computations("equilibria")
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", WORKER, json.dumps(parts)],
            cwd=ROOT,
            env=os.environ | {cache.ENV_VAR: str(tmp_path / f"disk{i}")},
            stdout=subprocess.PIPE,
            text=True,
        )
        for i in range(4)
    ]
    answers = [json.loads(p.communicate(timeout=60)[0]) for p in procs]
    assert len({a["by"] for a in answers}) == 1  # the computer's writes are flushed at its exit
    assert cache.shared_computations("equilibria") == before + 1


def test_a_lock_left_by_a_killed_server_expires(shared, client, monkeypatch):
    """kill -9 cannot release a lock, so every lock has a PX expiry: the waiter computes after it
    (here the store's lock time is 1 s; the lock is one a dead server left)."""
    monkeypatch.setitem(cache.STORES, "check", cache.Store("check", ttl_seconds=60, lock_seconds=1))
    parts = {"spec": "dead", "n": time.time()}
    client.set(rkey("check", parts, ":lock"), "dead-server", px=1000)
    start = time.monotonic()
    assert cache.get_or_compute("check", parts, lambda: {"ok": 1}) == {"ok": 1}
    assert 0.8 < time.monotonic() - start < 5


def test_when_redis_goes_away_values_are_computed_and_kept_on_disk(tmp_path, monkeypatch, caplog):
    proc, url = start_redis(tmp_path)
    monkeypatch.setenv(cache.REDIS_ENV_VAR, url)
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path / "disk"))
    monkeypatch.setitem(cache._redis_state, "down_until", 0.0)
    monkeypatch.setitem(cache._redis_state, "logged", False)
    monkeypatch.setattr(cache.cache_redis, "RETRY_SECONDS", 0.0)  # probe Redis at every call
    assert cache.get_or_compute("newton", {"away": 0}, lambda: {"i": 0}) == {"i": 0}
    stop(proc)
    with caplog.at_level(logging.WARNING, logger="mechanics.cache"):
        for i in range(1, 4):
            assert cache.get_or_compute("newton", {"away": i}, lambda i=i: {"i": i}) == {"i": i}
            assert cache.flush()
    assert len([r for r in caplog.records if "Redis is unreachable" in r.message]) == 1
    assert len(list((tmp_path / "disk" / "newton").glob("*.entry"))) == 3


# --- two app servers, one Redis -----------------------------------------------------------------


def start_server(redis_url: str, disk: Path) -> tuple[subprocess.Popen, str]:
    port = free_port()
    env = os.environ | {
        cache.REDIS_ENV_VAR: redis_url,
        cache.ENV_VAR: str(disk),
        "LAGRANGE_LAB_POOL_WORKERS": "1",  # two cores: keep the machine for the servers
    }
    proc = subprocess.Popen(
        [sys.executable, "-m", "uvicorn", "app.main:app", "--port", str(port)]
        + ["--host", "127.0.0.1", "--log-level", "warning"],
        cwd=ROOT,
        env=env,
    )
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 60
    while True:
        try:
            urllib.request.urlopen(f"{url}/healthz", timeout=1)
            return proc, url
        except OSError:
            if time.monotonic() > deadline or proc.poll() is not None:
                proc.kill()
                pytest.fail("the app server did not start")
            time.sleep(0.2)


@pytest.fixture(scope="module")
def servers(redis_url: str, tmp_path_factory) -> Iterator[list[str]]:
    started = [start_server(redis_url, tmp_path_factory.mktemp(f"disk{i}")) for i in range(2)]
    yield [url for _, url in started]
    for proc, _ in started:
        stop(proc)


def derive(url: str, scene_id: str) -> tuple[int, dict, tuple[float, float]]:
    """POST /derive of a built-in scene: status, body, and when it was sent and answered."""
    request = urllib.request.Request(
        f"{url}/api/v1/derive",
        data=json.dumps({"scene_id": scene_id}).encode(),
        headers={"content-type": "application/json"},
    )
    start = time.monotonic()
    with urllib.request.urlopen(request, timeout=120) as answer:
        return answer.status, json.loads(answer.read()), (start, time.monotonic())


def computed(client, expected: int | None = None, seconds: float = 5.0) -> int:
    """The fleet's count of derivations; with ``expected``, once it reaches it or ``seconds``
    have passed: servers write to Redis from a background thread, milliseconds after they
    answer (so a computation too many is waited for before it is ruled out)."""
    deadline = time.monotonic() + seconds
    while True:
        count = int(client.get(f"{cache.REDIS_PREFIX}computed:derivation") or 0)
        if expected is None or count >= expected or time.monotonic() > deadline:
            return count
        time.sleep(0.02)


def test_a_derivation_computed_by_one_server_is_served_by_the_other(servers, client):
    a, b = servers
    before = computed(client)
    status_a, first, _ = derive(a, "double_pendulum")
    assert status_a == 200 and computed(client, before + 1) == before + 1
    assert any(k.startswith(b"lagrange-lab:derivation:") for k in client.keys("lagrange-lab:*"))
    status_b, second, _ = derive(b, "double_pendulum")
    assert status_b == 200 and second == first
    # the second server did not derive it again (a second count would have arrived within 1 s)
    assert computed(client, before + 2, seconds=1.0) == before + 1


def test_concurrent_identical_requests_to_both_servers_cost_one_computation(servers, client):
    before = computed(client)
    urls = servers * 4
    with concurrent.futures.ThreadPoolExecutor(len(urls)) as pool:
        answers = list(pool.map(lambda url: derive(url, "elastic_pendulum"), urls))
    assert {status for status, _, _ in answers} == {200}
    assert all(body == answers[0][1] for _, body, _ in answers)
    # Every request was sent before any was answered: all eight were waiting at once...
    assert max(sent for _, _, (sent, _) in answers) < min(done for _, _, (_, done) in answers)
    assert computed(client, before + 2, seconds=1.0) == before + 1  # ...for one computation


def test_the_servers_keep_answering_when_redis_goes_away(tmp_path):
    """Its own Redis and servers: Redis stops, a derivation nobody cached is still a 200."""
    proc, url = start_redis(tmp_path)
    started = [start_server(url, tmp_path / f"disk{i}") for i in range(2)]
    try:
        assert derive(started[0][1], "simple_pendulum")[0] == 200
        stop(proc)
        for _, server in started:
            status, body, _ = derive(server, "bead_on_hoop")
            assert status == 200 and body["equations"]["eom"]
    finally:
        for p, _ in started:
            stop(p)
