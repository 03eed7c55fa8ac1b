"""A share link's atol survives the page (hostile play-test: a link made with rtol 1e-6 and atol
1e-12 redirected with ``atol=1e-12`` in its query, but the page never read it, rewrote its
address without it and ran with atol = rtol). The page's own query functions
(static/js/integrator.js readSettings, static/js/controls.js writeQuery) run in node on the query
the server's redirect writes, and the address they write back is read by the server's export of
the same run; the browser side (the runs the page requests) is in
tests/browser/test_share_editor_page.py.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import pytest
from fastapi.testclient import TestClient

from app.main import app

ROOT = Path(__file__).resolve().parents[2]
NODE = shutil.which("node")
client = TestClient(app)

#: The page reading a query (as scene.js does on load) and writing its address back.
PAGE = """
const root = process.argv[1];
const { readSettings, isFixed } = await import(root + "/static/js/integrator.js");
const { readValues, writeQuery } = await import(root + "/static/js/controls.js");
const { readFileSync } = await import("node:fs");
const { spec, query } = JSON.parse(readFileSync(0, "utf8"));
const settings = readSettings(new URLSearchParams(query));
const { params, initial } = readValues(spec, new URLSearchParams(query));
const written = writeQuery({ params, initial, settings, fixed: isFixed });
console.log(JSON.stringify({ settings, written }));
"""

STATE = {
    "scene_id": "double_pendulum",
    "method": "DOP853",
    "rtol": 1e-6,
    "atol": 1e-12,
    "t_end": 30,
}


def page(query: str) -> dict:
    """What the page keeps of ``query``: its settings and the address it writes."""
    spec = client.get("/api/v1/scenes/double_pendulum").json()["spec"]
    out = subprocess.run(
        [NODE, "--input-type=module", "-e", PAGE, str(ROOT)],
        input=json.dumps({"spec": spec, "query": query}),
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    return json.loads(out.stdout)


def redirect_query(state: dict) -> str:
    link = client.post("/api/v1/export/share", json=state)
    assert link.status_code == 200, link.text
    opened = client.get(link.json()["url"], follow_redirects=False)
    assert opened.status_code == 303
    return urlsplit(opened.headers["location"]).query


@pytest.mark.skipif(NODE is None, reason="node is not installed")
def test_the_page_keeps_a_shared_atol_in_its_settings_and_its_address():
    query = redirect_query(STATE)
    kept = page(query)
    assert float(kept["settings"]["tol"]) == STATE["rtol"]
    assert float(kept["settings"]["atol"]) == STATE["atol"]
    written = parse_qs(kept["written"])
    assert [float(x) for x in written["tol"]] == [STATE["rtol"]]
    assert [float(x) for x in written["atol"]] == [STATE["atol"]]
    # the address the page writes is the same run for the server: its script integrates with
    # the shared atol, not rtol
    script = client.get(f"/api/v1/export/scenes/double_pendulum/run.py?{kept['written']}")
    assert script.status_code == 200, script.text
    lines = script.text.splitlines()
    assert "ATOL = 1e-12" in lines and "RTOL = 1e-06" in lines


@pytest.mark.skipif(NODE is None, reason="node is not installed")
def test_an_atol_equal_to_rtol_or_unreadable_is_the_one_tolerance():
    """No second tolerance appears where the link had one: atol = rtol writes tol alone, and an
    atol the page cannot read as a positive number is not kept (the run uses tol for both)."""
    for query in (
        redirect_query({**STATE, "atol": STATE["rtol"]}),
        "method=DOP853&tol=1e-06&atol=abc&t_end=30",
        "method=DOP853&tol=1e-06&atol=-1e-12&t_end=30",
    ):
        kept = page(query)
        assert kept["settings"]["atol"] is None, query
        assert "atol" not in parse_qs(kept["written"]), query
    # a fixed-step method writes no tolerance at all, the link's atol included
    kept = page("method=rk4&dt=0.01&atol=1e-12&tol=1e-06")
    written = parse_qs(kept["written"])
    assert "atol" not in written and "tol" not in written and written["dt"] == ["0.01"]
