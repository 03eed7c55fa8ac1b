"""Limits of an HTTP request that hold however the app is run (issue 24, item 4 and item 6):
``LAGRANGE_LAB_MAX_BODY_BYTES`` sets the body limit."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from servers import free_port, serving

ROOT = Path(__file__).resolve().parents[2]

POST_SIZES = """
import json
from fastapi.testclient import TestClient
from app.main import app
client = TestClient(app)
out = []
for size in (1500, 2500):
    body = b'{"scene_id": "simple_pendulum", "title": "' + b"x" * (size - 47) + b'"}'
    r = client.post("/api/v1/derive", content=body, headers={"content-type": "application/json"})
    out.append([len(body), r.status_code, r.json()])
print(json.dumps(out))
"""


def test_the_body_limit_is_the_one_the_environment_sets():
    env = {**os.environ, "LAGRANGE_LAB_MAX_BODY_BYTES": "2000", "LAGRANGE_LAB_WARM": "0"}
    done = subprocess.run(
        [sys.executable, "-c", POST_SIZES],
        env=env,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    (small, big) = json.loads(done.stdout.splitlines()[-1])
    assert small[0] <= 2000 and small[1] == 422  # read (and refused for its extra field)
    assert big[0] > 2000 and big[1] == 413
    assert big[2] == {"detail": [{"field": "body", "message": "request body over 2000 bytes"}]}


# -- real servers, every documented way to run the app ------------------------------------------
#
# Each is started with short limits (1 s for headers, 2 s for a body, 32 KiB of headers, 6
# connections per client) and attacked over loopback with raw sockets, bounded in count and time.

LIMITS = {
    "LAGRANGE_LAB_HEADER_SECONDS": "1",
    "LAGRANGE_LAB_BODY_SECONDS": "2",
    "LAGRANGE_LAB_MAX_HEADER_BYTES": "32768",
    "LAGRANGE_LAB_CLIENT_CONNECTIONS": "6",
    "LAGRANGE_LAB_WARM": "0",
    "LAGRANGE_LAB_POOL_WORKERS": "1",
}
WAYS = {
    "lagrange-lab serve": ["-m", "app", "serve", "--port", "{port}"],
    "python -m uvicorn app.main:app": ["-m", "uvicorn", "app.main:app", "--port", "{port}"],
    "gunicorn recipe": [
        *("-m", "gunicorn", "app.main:app", "-k", "uvicorn.workers.UvicornWorker"),
        *("-w", "1", "-b", "127.0.0.1:{port}"),
    ],
}


@pytest.fixture(scope="module", params=list(WAYS))
def server(request, tmp_path_factory):
    if request.param == "gunicorn recipe" and not os.environ.get("CI"):
        pytest.importorskip("gunicorn")
    port = free_port()
    env = {**os.environ, **LIMITS, "LAGRANGE_LAB_CACHE": str(tmp_path_factory.mktemp("cache"))}
    command = [sys.executable, *(a.format(port=port) for a in WAYS[request.param])]
    with serving(command, port, env=env, cwd=ROOT, stderr=subprocess.DEVNULL) as (_, proc):
        yield port, proc.pid


def _rss_mib(pid: int) -> float:
    """Resident memory of the server and its children (gunicorn's worker is a child)."""
    total = 0.0
    for p in [pid, *_children(pid)]:
        for line in Path(f"/proc/{p}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                total += int(line.split()[1]) / 1024
    return total


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(c) for c in path.read_text().split()] if path.exists() else []


def _connect(port: int, source: str = "127.0.0.1") -> socket.socket:
    s = socket.socket()
    s.settimeout(10)
    s.bind((source, 0))
    s.connect(("127.0.0.1", port))
    return s


def _read_all(s: socket.socket, seconds: float) -> bytes:
    """What the server sends until it closes (or ``seconds`` pass)."""
    s.settimeout(seconds)
    data = b""
    try:
        while chunk := s.recv(65536):
            data += chunk
    except (TimeoutError, ConnectionResetError):
        pass
    return data


def _get(port: int, extra: bytes = b"", source: str = "127.0.0.1") -> bytes:
    with _connect(port, source) as s:
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: test\r\n" + extra + b"Connection: close\r\n\r\n")
        return _read_all(s, 10)


def test_headers_past_the_limit_are_a_431_read_no_further(server):
    port, pid = server
    before = _rss_mib(pid)
    answers, sent = [], []
    for _ in range(4):  # 4 × 32 MiB offered: 128 MiB if the server read them
        with _connect(port) as s:
            s.sendall(b"GET / HTTP/1.1\r\nHost: test\r\nX-Big: ")
            n, chunk = 0, b"a" * 65536
            try:
                while n < 32 * 1024 * 1024:
                    n += s.send(chunk)
            except OSError:
                pass
            sent.append(n)
            answers.append(_read_all(s, 5))
    assert all(a.startswith(b"HTTP/1.1 431") for a in answers), answers
    assert b'"field":"headers"' in answers[0].replace(b" ", b"")
    assert max(sent) < 8 * 1024 * 1024  # the server stopped reading near the limit
    assert _rss_mib(pid) - before < 40
    assert _get(port, b"X-Fine: " + b"b" * 8000 + b"\r\n").startswith(b"HTTP/1.1 200")


@pytest.mark.parametrize(
    "framing",
    [
        b"Content-Length: -5\r\n",
        b"Content-Length: 99999999999999999999\r\n",
        b"Content-Length: 3\r\nContent-Length: 4\r\n",
        b"X-Nul: a\x00b\r\n",
    ],
)
def test_a_request_the_server_cannot_parse_is_a_400_in_the_one_error_shape(server, framing):
    """Hostile play-test (2026-12-02): uvicorn answered these with a plain-text 'Invalid HTTP
    request received.'; every error a client can get is the JSON shape naming its field."""
    port, _ = server
    with _connect(port) as s:
        s.sendall(b"POST /api/v1/derive HTTP/1.1\r\nHost: test\r\n" + framing + b"\r\nabc")
        answer = _read_all(s, 10)
    head, _, body = answer.partition(b"\r\n\r\n")
    assert head.startswith(b"HTTP/1.1 400"), answer
    assert b"application/json" in head.lower()
    assert json.loads(body)["detail"][0]["field"] == "request"
    assert _get(port).startswith(b"HTTP/1.1 200")


def test_a_body_that_trickles_is_a_408_and_the_connection_closes(server):
    port, _ = server
    with _connect(port) as s:
        s.sendall(
            b"POST /api/v1/derive HTTP/1.1\r\nHost: test\r\nContent-Type: application/json\r\n"
            b'Content-Length: 1000\r\n\r\n{"scene_id": '
        )
        started = time.monotonic()
        for _ in range(10):  # a byte every 0.5 s, as a slow-body attacker does
            time.sleep(0.5)
            try:
                s.send(b" ")
            except OSError:
                break
        answer = _read_all(s, 5)
        took = time.monotonic() - started
    assert answer.startswith(b"HTTP/1.1 408"), answer
    assert b"connection: close" in answer.lower()
    assert b'"field":"body"' in answer.replace(b" ", b"")
    assert took < 8


def test_a_body_a_route_ignores_does_not_keep_the_connection(server):
    port, _ = server
    with _connect(port) as s:
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: test\r\nContent-Length: 100000\r\n\r\nxx")
        started = time.monotonic()
        answer = _read_all(s, 8)  # the server closes after answering
    assert answer.startswith(b"HTTP/1.1 200")
    assert time.monotonic() - started < 4


def test_headers_that_never_finish_are_closed(server):
    port, _ = server
    with _connect(port) as s:
        s.sendall(b"GET / HTTP/1.1\r\nHost: test\r\n")
        started = time.monotonic()
        for _ in range(8):  # a header line every 0.4 s: the deadline is on the whole headers
            time.sleep(0.4)
            try:
                s.send(b"X-A: b\r\n")
            except OSError:
                break
        assert _read_all(s, 5) == b""
        assert time.monotonic() - started < 4


def test_a_reconnecting_slowloris_holds_at_most_its_share(server):
    """One client (127.0.0.2) opens 24 connections that never finish their headers, and opens
    them again as the server closes them; the server holds 6 of them, and another client is
    answered at once meanwhile."""
    port, _ = server
    held, refused = [], 0
    try:
        for _round in range(2):
            for _ in range(24):
                s = _connect(port, "127.0.0.2")
                s.sendall(b"GET / HTTP/1.1\r\nHost: test\r\n")
                held.append(s)
            time.sleep(0.3)
            still = []
            for s in held:
                s.settimeout(0.05)
                try:
                    data = s.recv(1000)
                except TimeoutError:
                    still.append(s)
                    continue
                assert data == b"" or data.startswith(b"HTTP/1.1 429"), data
                refused += 1
                s.close()
            held = still
            assert len(held) <= 6
            assert _get(port).startswith(b"HTTP/1.1 200")  # another client is served
            time.sleep(1.5)  # the header deadline closes the six; the attacker reconnects
    finally:
        for s in held:
            s.close()
    assert refused >= 2 * (24 - 6)
