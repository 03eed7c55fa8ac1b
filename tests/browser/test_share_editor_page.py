"""The editor and share links as a hostile play-test left them:

- a valid spec that leaves out what the schema defaults (gravity's direction, a frame's parent)
  broke the page ("spec.gravity.direction is not iterable", and a note blaming the server);
- a link's atol (rtol 1e-6, atol 1e-12) was dropped from the address, the panel and the runs;
- a shared spec opened in the editor lost its token from the address, so a reload opened the
  simple_pendulum template instead.

The expected defaults are read from the server's own schema (/openapi.json), not written here.
"""

from __future__ import annotations

import json
from urllib.parse import parse_qs, urlparse

import pytest
from test_scene_page_details import api  # a GET or POST of the API, its JSON answer

pytestmark = pytest.mark.browser

#: A swing whose spec leaves gravity's direction and the body's kind to the schema's defaults.
SWING = {
    "title": "Swing, direction left out",
    "coordinates": ["phi"],
    "parameters": {"m": 2.0, "L": 0.7, "g": 9.81},
    "initial": {"phi": 0.4},
    "bodies": [{"name": "seat", "mass": "m", "position": ["L*sin(phi)", "-L*cos(phi)", 0]}],
    "gravity": {"acceleration": "g"},
}


def ran(page, timeout: float = 90_000) -> None:
    """The page's run arrived, or failed: either way it is over, and nothing is in flight."""
    page.page.wait_for_function(
        "(() => { const c = document.querySelector('#canvas');"
        " return c && (c.dataset.lastQ || c.dataset.error); })()",
        timeout=timeout,
    )
    page.settle(timeout)


def ran_cleanly(page) -> None:
    p = page.page
    assert p.get_attribute("#canvas", "data-error") is None
    assert p.locator(".stale-note").count() == 0  # no "which the server refused"
    assert page.errors == []


def address(p) -> dict[str, list[str]]:
    return parse_qs(urlparse(p.url).query)


class Requests:
    """The JSON bodies the page POSTs to one API path, while the block runs."""

    def __init__(self, p, path: str) -> None:
        self.p, self.path, self.bodies = p, path, []

    def _seen(self, request) -> None:
        if request.method == "POST" and urlparse(request.url).path == self.path:
            self.bodies.append(json.loads(request.post_data or "{}"))

    def __enter__(self) -> Requests:
        self.p.on("request", self._seen)
        return self

    def __exit__(self, *exc) -> None:
        self.p.remove_listener("request", self._seen)


def test_the_geometry_reads_a_left_out_default_as_the_schema_does(server, page):
    """SceneGeometry of a spec without gravity's direction (a frame without its parent) is the
    geometry of the same spec with the schema's default written in."""
    schemas = api(server, "/openapi.json")["components"]["schemas"]
    down = schemas["Gravity"]["properties"]["direction"]["default"]
    parent = schemas["Frame"]["properties"]["parent"]["default"]
    p = page.page
    p.goto(f"{server}/editor")
    page.settle()
    compared = p.evaluate(
        """async ([down, parent]) => {
          const { SceneGeometry } = await import('/static/js/geometry.js');
          const post = (body) => fetch('/api/v1/simulate', { method: 'POST',
            headers: { 'content-type': 'application/json' }, body: JSON.stringify(body) })
            .then((r) => r.json());
          const seen = (g) => JSON.stringify({ down: g.down, gravity: g.hasGravity, links: g.links,
            cones: g.cones, hoops: g.hoops, tracks: g.tracks, supports: g.supports });
          const out = {};
          for (const id of ['simple_pendulum', 'particle_in_cone']) {
            const { spec } = await (await fetch(`/api/v1/scenes/${id}`)).json();
            const run = await post({ scene_id: id, t_end: 2, fps: 30 });
            const written = structuredClone(spec), left = structuredClone(spec);
            written.gravity.direction = down;
            delete left.gravity.direction;
            for (const f of written.frames || []) f.parent = parent;
            for (const f of left.frames || []) delete f.parent;
            let error = null, a = null;
            try { a = seen(new SceneGeometry(left, run)); } catch (e) { error = String(e); }
            out[id] = { left: a, written: seen(new SceneGeometry(written, run)), error,
              cones: new SceneGeometry(written, run).cones.length };
          }
          return out;
        }""",
        [down, parent],
    )
    for scene_id, seen in compared.items():
        assert seen["error"] is None, scene_id
        assert seen["left"] == seen["written"], scene_id
    assert json.loads(compared["simple_pendulum"]["written"])["down"] == [0, -1, 0]
    assert compared["particle_in_cone"]["cones"] == 1  # the frame's parent is what finds it
    assert page.errors == []


def test_the_editor_runs_a_spec_that_leaves_gravitys_direction_out(server, page):
    p = page.page
    p.goto(f"{server}/editor?from=simple_pendulum")
    p.wait_for_function("document.querySelector('#spec').value.includes('bodies')")
    spec = json.loads(p.input_value("#spec"))
    spec["gravity"] = {"acceleration": "g"}
    p.fill("#spec", json.dumps(spec, indent=2))
    p.click("#derive")
    ran(page)
    ran_cleanly(page)
    assert p.locator("#spec-errors li").count() == 0


def test_a_shared_spec_keeps_its_token_and_atol_through_a_reload(server, page):
    state = {
        "scene": SWING,
        "parameters": {"L": 0.9},
        "initial": {"phi": 0.25},
        "method": "DOP853",
        "rtol": 1e-6,
        "atol": 1e-12,
        "t_end": 5,
    }
    link = api(server, "/api/v1/export/share", state)
    p = page.page
    p.goto(f"{server}{link['url']}")
    ran(page)
    ran_cleanly(page)
    assert urlparse(p.url).path == "/editor"
    assert json.loads(p.input_value("#spec")) == SWING
    here = address(p)
    assert here["share"] == [link["token"]]
    assert [float(x) for x in here["tol"]] == [1e-6]
    assert [float(x) for x in here["atol"]] == [1e-12]
    assert "1e-12" in p.inner_text("#atol-note")
    # a value moved, then the page reloaded: the same spec, with the value as it was left
    p.fill("#n-L", "1.1")
    p.dispatch_event("#n-L", "change")
    p.wait_for_function("new URLSearchParams(location.search).get('L') === '1.1'")
    ran(page)
    p.reload()
    ran(page)
    ran_cleanly(page)
    assert json.loads(p.input_value("#spec")) == SWING
    assert float(p.get_attribute("#n-L", "data-exact") or p.input_value("#n-L")) == 1.1
    assert address(p)["share"] == [link["token"]]
    assert [float(x) for x in address(p)["atol"]] == [1e-12]
    # shared again from here: the spec as written and the link's atol
    with Requests(p, "/api/v1/export/share") as shared:
        p.click("#share")
        p.wait_for_function("!document.querySelector('#share-url').hidden")
    (body,) = shared.bodies
    assert body["scene"] == SWING and body["rtol"] == 1e-6 and body["atol"] == 1e-12
    # another spec derived: the token no longer describes the page, and leaves the address
    p.fill("#spec", json.dumps({**SWING, "title": "Another swing"}, indent=2))
    p.click("#derive")
    p.wait_for_function("!new URLSearchParams(location.search).has('share')")
    ran(page)
    assert page.errors == []


def test_a_shared_atol_stays_in_the_scene_pages_address_until_a_tolerance_is_picked(server, page):
    state = {"scene_id": "double_pendulum", "method": "DOP853", "rtol": 1e-6, "atol": 1e-12}
    link = api(server, "/api/v1/export/share", {**state, "t_end": 5})
    p = page.page
    p.goto(f"{server}{link['url']}")
    ran(page)
    ran_cleanly(page)
    here = address(p)  # rewritten by the page after its run
    assert [float(x) for x in here["tol"]] == [1e-6] and [float(x) for x in here["atol"]] == [1e-12]
    assert "1e-12" in p.inner_text("#atol-note")
    with Requests(p, "/api/v1/export/share") as shared:
        p.click("#share")
        p.wait_for_function("!document.querySelector('#share-url').hidden")
    assert shared.bodies[0]["rtol"] == 1e-6 and shared.bodies[0]["atol"] == 1e-12
    # one tolerance picked in the panel is rtol and atol again
    p.select_option("#tol", "1e-9")
    p.wait_for_function("!new URLSearchParams(location.search).has('atol')")
    ran(page)
    assert p.locator("#atol-note").count() == 0
    assert "rtol = atol" in p.inner_text("#tol-box")
    assert page.errors == []


def test_the_runs_a_shared_link_makes_carry_its_atol(server, page):
    p = page.page
    for state in (
        {"scene_id": "double_pendulum", "method": "DOP853", "rtol": 1e-6, "atol": 1e-12},
        {"scene": SWING, "method": "DOP853", "rtol": 1e-6, "atol": 1e-12},
    ):
        link = api(server, "/api/v1/export/share", {**state, "t_end": 5})
        with Requests(p, "/api/v1/simulate") as runs:
            p.goto(f"{server}{link['url']}")
            ran(page)
        # the runs of the motion (an equilibrium's sketch is a one-sample run of no method)
        motion = [b for b in runs.bodies if "method" in b]
        assert motion, state
        assert all(b["rtol"] == 1e-6 and b["atol"] == 1e-12 for b in motion), motion
