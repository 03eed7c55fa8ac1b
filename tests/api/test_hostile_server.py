"""The server's answers to a hostile play-test (third round): a posted scene's live module under
a production server (``--workers 2``), a script export of a run /simulate refuses, request
parsing that answers every malformed request alike, and CSV comments that stay one line each.

Each expectation is independent of the code under test: the module must hash to the digest in its
URL (sha256, as the POST said), the script export must refuse exactly what /simulate refuses for
the same request, a malformed body must get the 422 of plain malformed JSON, and a CSV must split
into as many lines as ``str.splitlines()`` — the reader's own rule — says it has.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import httpx
import pytest
from fastapi.testclient import TestClient
from servers import free_port, serving

from app.main import app

ROOT = Path(__file__).resolve().parents[2]
client = TestClient(app)

PENDULUM = {
    "title": "Pendulum",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]}],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    "initial": {"theta": 1.0},
}


def only_problem(r: httpx.Response, status: int) -> dict[str, str]:
    """The one {field, message} of an error answer in the one shape, with its status."""
    assert r.status_code == status, r.text
    detail = r.json()["detail"]
    assert isinstance(detail, list) and len(detail) == 1, detail
    assert set(detail[0]) == {"field", "message"}, detail
    return detail[0]


# --- 1. a posted scene's module, whichever worker a GET reaches ---------------------------------


@pytest.mark.slow
def test_a_posted_module_is_served_by_every_worker_of_a_two_worker_server(tmp_path):
    """README's production mode. Each GET opens its own connection, so the kernel spreads them
    over both workers: with the module in one worker's memory, 20 GETs all reaching that one
    would happen with probability 2**-19."""
    port = free_port()
    env = {
        **os.environ,
        "LAGRANGE_LAB_CACHE": str(tmp_path / "cache"),
        "LAGRANGE_LAB_WARM": "0",
    }
    command = [sys.executable, "-m", "app", "serve", "--port", str(port)]
    command += ["--workers", "2", "--pool-workers", "1"]
    with serving(command, port, env=env, cwd=ROOT, stderr=subprocess.DEVNULL) as (url, _):
        posted = httpx.post(
            f"{url}/api/v1/scenes/live", json={"scene": PENDULUM}, timeout=120, trust_env=False
        )
        assert posted.status_code == 200, posted.text
        module = posted.json()["module"]
        digest = module.removeprefix("/api/v1/scenes/live/").removesuffix(".js")
        statuses, sources = [], set()
        for _ in range(20):
            r = httpx.get(
                url + module, headers={"connection": "close"}, timeout=30, trust_env=False
            )
            statuses.append(r.status_code)
            sources.add(r.text)
    assert statuses == [200] * 20
    (source,) = sources
    assert hashlib.sha256(source.encode()).hexdigest()[:16] == digest
    assert "export function rhs(t, y, p, out)" in source


FORGE = """
import sys
from app.routes.scenes import LIVE_STORE
from mechanics import cache
for digest, source in zip(sys.argv[1::2], sys.argv[2::2]):
    cache.get_or_compute(LIVE_STORE, {"digest": digest}, lambda: {"source": source})
"""


def test_a_stored_module_that_does_not_hash_to_its_digest_is_not_served(tmp_path, monkeypatch):
    """The store is shared (a disk, Redis) with other processes: what this one reads back from it
    must be the module the URL names. Another process writes one entry that lies about its
    digest and one that does not."""
    monkeypatch.setenv("LAGRANGE_LAB_CACHE", str(tmp_path))
    forged, source = "0123456789abcdef", "export const n = 1;\n"
    honest = hashlib.sha256(source.encode()).hexdigest()[:16]
    writer = [sys.executable, "-c", FORGE, forged, "alert(1)", honest, source]
    subprocess.run(writer, check=True, cwd=ROOT, env={**os.environ})
    problem = only_problem(client.get(f"/api/v1/scenes/live/{forged}.js"), 404)
    assert problem["field"] == "digest"
    r = client.get(f"/api/v1/scenes/live/{honest}.js")
    assert r.status_code == 200 and r.text == source


# --- 2. a script of a run /simulate refuses is refused alike -----------------------------------


def test_the_script_of_a_run_that_overflows_is_refused_as_its_trajectory_is():
    base = "/api/v1/export/scenes/simple_pendulum"
    trajectory = only_problem(client.get(f"{base}/trajectory.csv?g=1e308"), 422)
    script = only_problem(client.get(f"{base}/run.py?g=1e308"), 422)
    assert script == trajectory and trajectory["field"] == "parameters.g"
    request = {"scene_id": "simple_pendulum", "parameters": {"g": 1e308}}
    simulated = only_problem(client.post("/api/v1/simulate", json=request), 422)
    assert only_problem(client.post("/api/v1/export/script", json=request), 422) == simulated
    posted = {"scene": PENDULUM, "parameters": {"g": 1e308}}
    simulated = only_problem(client.post("/api/v1/simulate", json=posted), 422)
    assert only_problem(client.post("/api/v1/export/script", json=posted), 422) == simulated


def test_the_script_of_an_ordinary_run_is_still_written():
    r = client.get("/api/v1/export/scenes/simple_pendulum/run.py?g=9.81&t_end=2")
    assert r.status_code == 200 and r.text.startswith("#!/usr/bin/env python3")


# --- 3. one error shape for a malformed request -------------------------------------------------

BODY_ROUTES = ["/api/v1/derive", "/api/v1/simulate", "/api/v1/export/trajectory"]


def post_raw(url: str, body: bytes | str):
    return client.post(url, content=body, headers={"content-type": "application/json"})


@pytest.mark.parametrize("url", BODY_ROUTES)
@pytest.mark.parametrize(
    "body, says",
    [
        ("[" * 100_000 + "]" * 100_000, "nested"),
        ('{"scene_id": ' + "7" * 5000 + "}", "digits"),
        (b'{"scene_id": "\xff"}', "UTF-8"),
    ],
    ids=["deeply nested", "5000-digit integer", "not UTF-8"],
)
def test_a_body_python_cannot_read_is_the_422_of_any_malformed_json(url, body, says):
    plain = only_problem(post_raw(url, '{"scene_id": '), 422)
    problem = only_problem(post_raw(url, body), 422)
    assert problem["field"] == plain["field"] == "body"
    assert problem["message"].startswith("invalid JSON: ") and says in problem["message"]


@pytest.mark.parametrize(
    "method, url, body",
    [
        (
            "POST",
            "/api/v1/export/trajectory?format=csv&format=json",
            {"scene_id": "simple_pendulum"},
        ),
        ("POST", "/api/v1/export/spec?format=toml&format=json", {"scene_id": "simple_pendulum"}),
        ("GET", "/api/v1/export/scenes/simple_pendulum/trajectory.csv?t_end=1&t_end=2", None),
        ("GET", "/api/v1/scenes/simple_pendulum/live.js?v=a&v=b", None),
        ("POST", "/api/v1/derive?scene_id=x&scene_id=y", {"scene_id": "simple_pendulum"}),
    ],
)
def test_a_query_key_given_twice_is_refused_everywhere(method, url, body):
    key = url.split("?")[1].split("=")[0]
    r = client.request(method, url, json=body)
    assert only_problem(r, 422) == {"field": key, "message": "given 2 times: give it once"}


def test_a_key_given_once_and_a_page_query_are_not_refused():
    r = client.post("/api/v1/export/trajectory?format=json", json={"scene_id": "simple_pendulum"})
    assert r.status_code == 200 and r.headers["content-type"] == "application/json"
    # a page's own query is its script's to read: no JSON error instead of the HTML page
    assert client.get("/scenes/simple_pendulum?m=1&m=2").status_code == 200


@pytest.mark.parametrize("raw", ["%EF%BC%91", "%D9%A1", "1%EF%BC%90"], ids=["１", "١", "1０"])
def test_only_ascii_numerals_are_read_in_a_query(raw):
    """Python's float() reads '１' as 1; the page's Number() reads it as NaN."""
    base = "/api/v1/export/scenes/simple_pendulum"
    for export in ("trajectory.csv", "run.py"):
        problem = only_problem(client.get(f"{base}/{export}?l={raw}"), 422)
        assert problem["field"] == "l" and "0-9" in problem["message"]
    assert client.get(f"{base}/trajectory.csv?l=1&t_end=1").status_code == 200


# --- 4. CSV comments: one line each --------------------------------------------------------------

BREAKS = "\u2028\x85\u2029\x0b\x0c\x1c\x1d\x1e\r\n"


def test_every_line_break_in_a_title_or_a_stop_message_stays_inside_its_comment():
    title = "A" + "B".join(BREAKS) + "Z"
    stop = {"name": "late", "message": "stopped\u2028here\x85now", "when": "1 - t"}
    spec = {**PENDULUM, "title": title, "stops": [stop]}
    r = client.post("/api/v1/export/trajectory?format=csv", json={"scene": spec, "t_end": 2})
    assert r.status_code == 200, r.text
    lines = r.text.splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    rows = list(csv.reader(io.StringIO("\n".join(lines[header:]))))
    assert rows[0][:2] == ["t [s]", "theta"]  # the header, and not a piece of a comment
    samples = rows[1:]
    assert all(len(row) == len(rows[0]) for row in samples)
    assert all(float(row[0]) <= 1.0 + 1e-9 for row in samples)  # the stop at t = 1 was run
    # the scene's title reads back exactly from its JSON comment
    (scene,) = [line for line in lines[:header] if line.startswith("# scene: ")]
    assert json.loads(scene.removeprefix("# scene: ")) == title
    assert any("stopped here now" in line for line in lines[:header])
