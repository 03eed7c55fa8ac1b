"""HTTP as a browser or a hostile client meets it: compression, caching, headers, HEAD, limits.

In-process checks use TestClient; what only a real server shows (a chunked body cut at the limit,
a connection that never finishes its headers) runs against ``python -m app serve`` on a free port.
"""

from __future__ import annotations

import math
import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import orjson
import pytest
from fastapi.testclient import TestClient
from servers import free_port, serving

from app.assets import IMMUTABLE, content_version
from app.main import LagrangeLab, app, internal_error
from app.paths import STATIC_DIR
from app.responses import ORJSONResponse, dumps

ROOT = Path(__file__).resolve().parents[2]
PAGES = ["/", "/scenes/double_pendulum", "/editor", "/docs", "/redoc"]
SECURITY_HEADERS = {
    "x-content-type-options": "nosniff",
    "x-frame-options": "DENY",
    "referrer-policy": "no-referrer",
}


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def local_urls(html: str) -> list[str]:
    """Every same-site URL a page names: src/href attributes and module imports."""
    return [a or b for a, b in re.findall(r'(?:src|href)="(/[^"]*)"|from "(/[^"]*)"', html)]


# -- JSON ------------------------------------------------------------------------------------


def test_orjson_answers_write_non_finite_numbers_as_null():
    data = {"E": [1.5, math.nan, math.inf], "q": np.array([-math.inf, 2.0]), "n": np.int32(3)}
    assert orjson.loads(dumps(data)) == {"E": [1.5, None, None], "q": [None, 2.0], "n": 3}
    response = ORJSONResponse(data)
    assert response.media_type == "application/json"
    assert b"NaN" not in response.body and b"Infinity" not in response.body


def test_a_simulate_answer_is_strict_json(client):
    r = client.post("/api/v1/simulate", json={"scene_id": "simple_pendulum", "t_end": 1.0})
    assert r.status_code == 200
    assert r.headers["content-type"] == "application/json"
    orjson.loads(r.content)  # strict: would refuse NaN or Infinity tokens


# -- compression -----------------------------------------------------------------------------


def test_answers_say_where_the_servers_time_went(client):
    """Server-Timing: "app" on every answer (arrival to first byte); a simulation adds its wait
    at the gate and its run, and a repeated one says it came from the memo."""

    def parts(r) -> dict[str, float]:
        return {
            m[1]: float(m[2])
            for m in re.finditer(r"(\w+);dur=([0-9.]+)", r.headers["server-timing"])
        }

    assert "app" in parts(client.get("/healthz"))
    body = {"scene_id": "simple_pendulum", "t_end": 0.75, "parameters": {"l": 1.2345}}
    first = parts(client.post("/api/v1/simulate", json=body))
    assert {"app", "gate", "thread", "run"} <= set(first)
    assert first["run"] <= first["thread"] <= first["app"] + 0.2  # each inside the other
    assert "memo" in parts(client.post("/api/v1/simulate", json=body))


@pytest.mark.parametrize("url", ["/", "/scenes/double_pendulum", "/api/v1/scenes", "/openapi.json"])
def test_pages_and_json_are_gzipped(client, url):
    r = client.get(url, headers={"accept-encoding": "gzip"})
    assert r.status_code == 200
    assert r.headers["content-encoding"] == "gzip"
    assert "accept-encoding" in r.headers["vary"].lower()


def test_small_answers_and_clients_without_gzip_get_plain_bytes(client):
    assert "content-encoding" not in client.get("/healthz").headers
    r = client.get("/api/v1/scenes", headers={"accept-encoding": "identity"})
    assert "content-encoding" not in r.headers and r.json()


# -- static files under versioned URLs -------------------------------------------------------


def test_pages_load_every_asset_from_a_versioned_url_cached_for_a_year(client):
    for page in ["/", "/scenes/double_pendulum", "/editor", "/docs"]:
        urls = local_urls(client.get(page).text)
        assets = [u for u in urls if u.startswith("/static/")]
        assert assets, page
        for url in assets:
            assert re.search(r"/[0-9a-f]{12}/", url), f"{page} loads {url} unversioned"
            r = client.get(url, headers={"accept-encoding": "gzip"})
            assert r.status_code == 200, url
            assert r.headers["cache-control"] == IMMUTABLE, url


def test_scene_page_loads_plotly_and_mathjax_gzipped_and_immutable(client):
    html = client.get("/scenes/double_pendulum").text
    assert not [u for u in local_urls(html) if "plotly" in u]  # plotly waits for the motion
    (scene_js,) = [u for u in local_urls(html) if u.endswith("js/scene.js")]
    # static/js/lazy.js loads it from the page's own versioned folder when the plots are drawn
    lazy_plotly = scene_js.replace("js/scene.js", "vendor/plotly-basic/plotly.min.js")
    (mathjax,) = [u for u in local_urls(html) if u.endswith("tex-svg.js")]
    for url in (lazy_plotly, mathjax):
        r = client.get(url, headers={"accept-encoding": "gzip"})
        assert r.headers["content-encoding"] == "gzip"
        assert r.headers["cache-control"] == IMMUTABLE
        assert int(r.headers["content-length"]) < 0.4 * len(r.content)  # httpx decoded it
        raw = client.get(url, headers={"accept-encoding": "identity"})
        assert "content-encoding" not in raw.headers
        assert raw.content == r.content


def test_unversioned_static_urls_revalidate_with_their_etag(client):
    r = client.get("/static/js/scene.js", headers={"accept-encoding": "gzip"})
    assert r.status_code == 200 and r.headers["cache-control"] == "no-cache"
    again = client.get(
        "/static/js/scene.js",
        headers={"accept-encoding": "gzip", "if-none-match": r.headers["etag"]},
    )
    assert again.status_code == 304 and again.content == b""
    plain = client.get("/static/js/scene.js", headers={"accept-encoding": "identity"})
    assert plain.headers["etag"] != r.headers["etag"]  # each encoding has its own tag
    assert (
        client.get(
            "/static/js/scene.js", headers={"if-none-match": plain.headers["etag"]}
        ).status_code
        == 304
    )


def test_an_old_version_is_served_but_never_cached_for_a_year(client):
    r = client.get("/static/000000000000/js/scene.js")
    assert r.status_code == 200 and r.headers["cache-control"] == "no-cache"
    assert client.get("/static/js/no-such-file.js").status_code == 404


def test_the_version_follows_the_files_content(tmp_path):
    (tmp_path / "js").mkdir()
    (tmp_path / "js" / "a.js").write_text("export const a = 1;\n")
    version = content_version(tmp_path, recheck_seconds=0)
    first = version()
    assert version() == first
    (tmp_path / "js" / "a.js").write_text("export const a = 2;\n")
    assert version() != first
    (tmp_path / "js" / "b.js").write_text("")
    assert len({first, version()}) == 2


def test_modules_import_their_neighbours_relatively():
    """The versioned-folder scheme holds only while no module names /static/ itself: an absolute
    import would load a second, unversioned copy of a module beside the versioned one."""
    for path in sorted(STATIC_DIR.rglob("*.js")):
        text = path.read_text()
        static = re.findall(r'^\s*(?:import|export)\b[^"\n]*?\bfrom\s*"([^"]+)"', text, re.M)
        for target in static + re.findall(r'\bimport\(\s*"([^"]+)"\s*\)', text):
            assert target.startswith("./") or target.startswith("../"), f"{path.name}: {target}"


# -- API docs --------------------------------------------------------------------------------


@pytest.mark.parametrize("page", ["/docs", "/redoc"])
def test_api_docs_load_only_local_files(client, page):
    r = client.get(page)
    assert r.status_code == 200
    assert "http://" not in r.text and "https://" not in r.text
    assert 'nonce="' in r.text or page == "/redoc"
    for url in local_urls(r.text):
        assert client.get(url).status_code == 200, url


# -- headers, HEAD, errors -------------------------------------------------------------------


@pytest.mark.parametrize(
    "method,url,status",
    [
        ("GET", "/", 200),
        ("GET", "/api/v1/scenes", 200),
        ("GET", "/static/js/api.js", 200),
        ("GET", "/scenes/no_such_scene", 404),
        ("GET", "/api/v1/no-such-route", 404),
        ("POST", "/api/v1/derive", 422),
    ],
)
def test_every_response_carries_the_security_headers(client, method, url, status):
    r = client.request(method, url, json={} if method == "POST" else None)
    assert r.status_code == status
    for name, value in SECURITY_HEADERS.items():
        assert r.headers[name] == value
    csp = r.headers["content-security-policy"]
    assert "default-src 'self'" in csp and "frame-ancestors 'none'" in csp
    assert "http:" not in csp and "https:" not in csp and "'unsafe-eval'" not in csp


def test_inline_scripts_carry_this_responses_nonce(client):
    for page in PAGES:
        r = client.get(page)
        nonce = re.search(r"'nonce-([^']+)'", r.headers["content-security-policy"]).group(1)
        for tag in re.findall(r"<script\b[^>]*>", r.text):
            assert "src=" in tag or f'nonce="{nonce}"' in tag, (page, tag)
    first, second = (client.get("/").headers["content-security-policy"] for _ in range(2))
    assert first != second  # a fresh nonce per response


def test_an_unexpected_failure_is_a_json_500_with_the_headers():
    failing = LagrangeLab()
    failing.add_exception_handler(Exception, internal_error)

    @failing.get("/boom")
    def boom():
        raise RuntimeError("boom")

    r = TestClient(failing, raise_server_exceptions=False).get("/boom")
    assert r.status_code == 500
    assert r.json() == {"detail": "internal server error"}
    assert r.headers["x-content-type-options"] == "nosniff"


@pytest.mark.parametrize("url", [*PAGES, "/healthz", "/api/v1/scenes", "/static/js/scene.js"])
def test_head_answers_what_get_would_without_the_body(client, url):
    plain = {"accept-encoding": "identity"}
    head, get = client.head(url, headers=plain), client.get(url, headers=plain)
    assert head.status_code == 200
    assert head.content == b""
    assert head.headers["content-type"] == get.headers["content-type"]
    assert int(head.headers["content-length"]) == len(get.content)


def test_a_declared_body_over_the_limit_is_refused_unread(client):
    r = client.post(
        "/api/v1/derive",
        content=b"x",
        headers={"content-type": "application/json", "content-length": str(2 * 1024 * 1024)},
    )
    assert r.status_code == 413
    assert r.json() == {"detail": [{"field": "body", "message": "request body over 1 MiB"}]}


# -- a real server ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    """``lagrange-lab serve`` (its protocol and timeouts), with a 1 s header deadline."""
    port = free_port()
    env = {**os.environ, "LAGRANGE_LAB_CACHE": str(tmp_path_factory.mktemp("cache"))}
    command = [sys.executable, "-m", "app", "serve", "--port", str(port), "--timeout-headers", "1"]
    with serving(command, port, env=env, cwd=ROOT, stderr=subprocess.DEVNULL) as (_, proc):
        yield port, proc.pid


def _rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


def _post_chunked(port: int, mib: int) -> tuple[bytes, int]:
    """POST a chunked body of ``mib`` MiB to /api/v1/derive, reading while sending, as curl does;
    returns the answer and how many bytes went out before it came."""
    chunk = b"7" * 65536
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(
            b"POST /api/v1/derive HTTP/1.1\r\nHost: test\r\nContent-Type: application/json\r\n"
            b"Transfer-Encoding: chunked\r\n\r\n"
        )
        s.setblocking(False)
        sent, answer, deadline, sending = 0, b"", time.monotonic() + 30, True
        while time.monotonic() < deadline and not answer.endswith(b"}"):
            if sending and sent < mib * 1024 * 1024 and b"\r\n\r\n" not in answer:
                try:
                    s.send(b"%x\r\n%s\r\n" % (len(chunk), chunk))
                    sent += len(chunk)
                except BlockingIOError:
                    pass
                except OSError:  # the server closed its side: stop sending, read its answer
                    sending = False
            try:
                data = s.recv(65536)
                if not data:
                    break
                answer += data
            except BlockingIOError:
                time.sleep(0.001)
            except OSError:
                break
        return answer, sent


def test_a_chunked_body_over_the_limit_is_refused_as_it_streams(served):
    port, pid = served
    before = _rss_mib(pid)
    answer, sent = _post_chunked(port, mib=200)
    assert answer.startswith(b"HTTP/1.1 413")
    assert answer.endswith(b'{"detail":[{"field":"body","message":"request body over 1 MiB"}]}')
    assert sent < 40 * 1024 * 1024  # refused long before the 200 MiB were sent
    assert _rss_mib(pid) - before < 50  # never held in memory


def test_a_connection_that_never_finishes_its_headers_is_closed(served):
    port, _ = served
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.sendall(b"GET / HTTP/1.1\r\nHost: test\r\n")  # and nothing more
        started = time.monotonic()
        assert s.recv(100) == b""  # closed by the server
        assert time.monotonic() - started < 3
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.sendall(b"HEAD / HTTP/1.1\r\nHost: test\r\n\r\n")
        assert s.recv(100).startswith(b"HTTP/1.1 200")
