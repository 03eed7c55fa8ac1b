"""The first second of a scene page (issue 13, item 1), guarded by order, not by timings:

- the page carries its spec, derivation and live equations, so the derivation shows without a
  /derive request and the live preview needs no /live request;
- the live preview moves on the canvas before the server's run has arrived (the run is held back
  here with Playwright's routing, so "before" does not depend on the machine's speed);
- whatever the page waits for past 300 ms shows a progress bar that says what it is;
- the line under the animation says what is drawn, whichever of the preview and the server's run
  comes first (a play-test found 'live preview' left up in lecture mode at 1024 px).

Each test opens its own browser context: an empty cache, as on a student's first visit.
"""

from __future__ import annotations

import json

import pytest

pytestmark = pytest.mark.browser

#: Every animation frame from the page's first script on: does the line under the animation
#: name what the canvas draws? (data-kind "preview"/"server" against the canvas's data-source)
LABEL_PROBE = """
(() => {
  window.__label = { checked: 0, mismatches: [] };
  const tick = () => {
    const c = document.getElementById('canvas'), b = document.getElementById('live-badge');
    if (c && b && !b.hidden && c.dataset.source) {
      window.__label.checked++;
      const drawn = c.dataset.source === 'live' ? 'preview' : 'server';
      if (b.dataset.kind !== drawn && window.__label.mismatches.length < 5) {
        window.__label.mismatches.push([c.dataset.source, b.dataset.kind, b.textContent]);
      }
    }
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
})();
"""


class Held:
    """Requests whose URL contains ``part``, held until `release` (nothing reaches the server
    meanwhile, so the page's order of events is fixed by the test, not by the machine)."""

    def __init__(self, page, part: str) -> None:
        self.routes = []
        self.released = False
        page.route(f"**/*{part}*", self._hold)

    def _hold(self, route) -> None:
        if self.released:
            route.continue_()
        else:
            self.routes.append(route)

    def release(self) -> None:
        self.released = True
        for route in self.routes:
            route.continue_()
        self.routes.clear()


def _warm(ctx, server: str, scene: str) -> None:
    """The server's part of "a warm server" for one scene: its derivation and live equations
    made once (the warm-up at server start does every scene, in its own time)."""
    assert ctx.request.post(f"{server}/api/v1/derive", data={"scene_id": scene}).ok
    assert ctx.request.get(f"{server}/api/v1/scenes/{scene}/live").ok


def _moving(page, source: str, timeout: float = 60_000) -> None:
    """Wait until the canvas draws `source`'s run ('live' or 'server') and its frame changes."""
    page.wait_for_function(
        f"document.querySelector('#canvas').dataset.source === '{source}'"
        " && document.querySelector('#canvas').dataset.frame !== undefined",
        timeout=timeout,
    )
    first = page.get_attribute("#canvas", "data-frame")
    page.wait_for_function(
        f"document.querySelector('#canvas').dataset.frame !== '{first}'"
        f" && document.querySelector('#canvas').dataset.source === '{source}'",
        timeout=timeout,
    )


def test_the_page_carries_its_derivation_spec_and_live_equations(server, fresh):
    _warm(fresh, server, "double_pendulum")
    page = fresh.new_page()
    asked: list[str] = []
    page.on("request", lambda r: "/api/" in r.url and asked.append(r.url.split("?")[0]))
    page.goto(f"{server}/scenes/double_pendulum")
    page.wait_for_selector("#steps li.step", timeout=60_000)
    inline = json.loads(page.text_content("#scene-derivation"))
    # the same derivation the API answers, asked for here by the test itself
    answered = page.request.post(
        f"{server}/api/v1/derive", data={"scene_id": "double_pendulum"}
    ).json()
    assert inline == answered
    titles = page.eval_on_selector_all("#steps > li.step h3", "hs => hs.map(h => h.textContent)")
    assert len(titles) == len(answered["steps"])
    for title, step in zip(titles, answered["steps"], strict=True):
        assert step["title"] in title
    spec = json.loads(page.text_content("#scene-spec"))
    assert spec == page.request.get(f"{server}/api/v1/scenes/double_pendulum").json()
    live = json.loads(page.text_content("#scene-live"))
    assert live == page.request.get(f"{server}/api/v1/scenes/double_pendulum/live").json()
    page.wait_for_function("document.querySelector('#canvas').dataset.live === 'ready'")
    page.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=60_000)
    for path in ("/derive", "/scenes/double_pendulum", "/scenes/double_pendulum/live"):
        assert f"{server}/api/v1{path}" not in asked, asked
    # the live module itself is named for preloading, so it is fetched with the page
    preloads = page.eval_on_selector_all(
        "link[rel=modulepreload]", "ls => ls.map(l => l.getAttribute('href'))"
    )
    assert live["module"] in preloads


def test_the_preview_moves_before_the_servers_run_arrives(server, fresh):
    _warm(fresh, server, "double_pendulum")
    fresh.add_init_script(LABEL_PROBE)
    page = fresh.new_page()
    held = Held(page, "/api/v1/simulate")
    page.goto(f"{server}/scenes/double_pendulum")
    _moving(page, "live")
    assert held.routes and not held.released  # the server's run is still on its way
    badge = page.locator("#live-badge")
    assert badge.get_attribute("data-kind") == "preview"
    assert "the server's run is on its way" in badge.inner_text()
    assert page.get_attribute("html", "data-slow") and "Computing the motion" in (
        page.get_attribute("html", "data-slow")
    )
    held.release()
    _moving(page, "server")
    assert badge.get_attribute("data-kind") == "server"
    assert "server run" in badge.inner_text()
    seen = page.evaluate("window.__label")
    assert seen["checked"] > 0 and seen["mismatches"] == [], seen


#: Animation frames only when the test says (`window.__frame()`): what the page does between two
#: frames is then fixed by the test, as on a slow laptop whose frames come far apart.
MANUAL_FRAMES = """
(() => {
  let queue = [];
  window.requestAnimationFrame = (cb) => { queue.push(cb); return queue.length; };
  window.cancelAnimationFrame = () => {};
  window.__frame = () => {
    const due = queue;
    queue = [];
    due.forEach((cb) => cb(performance.now()));
  };
})();
"""


@pytest.mark.parametrize("order", ["live equations first", "server's run first"])
def test_the_label_says_what_is_drawn_in_lecture_mode_at_1024(server, browser, order):
    """The live equations and the server's run arrive with no animation frame between them, in
    either order (the play-test's race: a preview asked for, the server's run shown, then the
    preview drawn over it at the next frame with its 'live preview' line). The server's run
    stays on the canvas and the line under it says so."""
    ctx = browser.new_context(viewport={"width": 1024, "height": 768}, bypass_csp=True)
    try:
        _warm(ctx, server, "double_pendulum")
        ctx.add_init_script(MANUAL_FRAMES)
        ctx.add_init_script(LABEL_PROBE)
        page = ctx.new_page()
        run = Held(page, "/api/v1/simulate")
        live = Held(page, "/api/v1/scenes/double_pendulum/live.js")
        page.goto(f"{server}/scenes/double_pendulum?lecture=1", wait_until="commit")
        poll = {"polling": 50, "timeout": 60_000}
        page.wait_for_function("document.querySelector('#steps li.step')", **poll)
        page.wait_for_function("() => document.querySelector('#canvas').dataset.waiting", **poll)
        page.evaluate("window.__frame()")
        if order == "live equations first":
            live.release()
            page.wait_for_function("document.querySelector('#canvas').dataset.live", **poll)
            run.release()
            page.wait_for_function("document.querySelector('#canvas').dataset.lastQ", **poll)
        else:
            run.release()
            page.wait_for_function("document.querySelector('#canvas').dataset.lastQ", **poll)
            live.release()
            page.wait_for_function("document.querySelector('#canvas').dataset.live", **poll)
        assert page.get_attribute("#canvas", "data-live") == "ready"
        for _ in range(5):  # a preview asked for meanwhile would be drawn in these frames
            page.evaluate("window.__frame()")
        assert page.get_attribute("#canvas", "data-source") == "server"
        badge = page.locator("#live-badge")
        assert badge.get_attribute("data-kind") == "server"
        assert "live preview" not in badge.inner_text()
        assert "server run" in badge.inner_text()
        seen = page.evaluate("window.__label")
        assert seen["checked"] > 0 and seen["mismatches"] == [], seen
    finally:
        ctx.close()


def test_a_slow_answer_shows_progress_saying_what_it_waits_for(server, fresh):
    page = fresh.new_page()
    page.goto(f"{server}/scenes/simple_pendulum")
    page.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=60_000)
    page.wait_for_function(
        "() => (document.documentElement.dataset.pending || '0') === '0'", timeout=60_000
    )
    page.wait_for_function("!document.documentElement.dataset.slow", timeout=60_000)
    held = Held(page, "/api/v1/equilibria")
    page.click("#reset")  # asks for a new run and the equilibria again
    bar = page.locator("#progress")
    bar.wait_for(state="visible", timeout=10_000)
    assert bar.get_attribute("role") == "progressbar"
    assert "Finding equilibria" in bar.inner_text()
    held.release()
    bar.wait_for(state="hidden", timeout=90_000)  # the run and the equilibria, on a loaded machine
    assert page.get_attribute("html", "data-slow") is None
