"""A first visit (issue 13, item 1), guarded by what it must never do rather than by timings:
the catalog draws from one request, the canvas is never blank while the button says 'Pause', and
a scene page transfers at most 1.5 MB on a cold visit and 100 kB on a repeat (bytes on the wire,
compressed, headers included, as Chromium's network layer counts them).

Each test opens its own browser context, so its cache starts empty.
"""

from __future__ import annotations

import time

import pytest

pytestmark = pytest.mark.browser

COLD_LIMIT = 1_500_000
REPEAT_LIMIT = 100_000

#: From the page's first script on, every animation frame: was 'Pause' shown over a blank canvas
#: once the scene's script had taken the page over (it marks the canvas with data-waiting)?
BLANK_PROBE = """
(() => {
  window.__blank = { pause_over_blank: 0, checked: 0, before_script: 0 };
  let n = 0;
  const tick = () => {
    const play = document.getElementById('play'), c = document.getElementById('canvas');
    if (play && c && /Pause/.test(play.textContent) && (n++ % 3 === 0)) {
      if (c.dataset.waiting === undefined) window.__blank.before_script++;
      else {
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let ink = false;
        for (let i = 3; i < d.length; i += 4 * 97) if (d[i] !== 0) { ink = true; break; }
        window.__blank.checked++;
        if (!ink) window.__blank.pause_over_blank++;
      }
    }
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
})();
"""


def _settled(page, timeout: float = 90_000) -> None:
    page.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=timeout)
    page.wait_for_selector("#steps[data-typeset='1']", state="attached", timeout=timeout)
    page.wait_for_selector("#plot-q .main-svg", state="attached", timeout=timeout)
    page.wait_for_function(
        "() => (document.documentElement.dataset.pending || '0') === '0'", timeout=timeout
    )
    page.wait_for_timeout(500)


def _visit(ctx, url: str) -> dict[str, int]:
    """Open ``url`` in a new tab of ``ctx`` until it settles: bytes received per URL (0 for
    what came from the browser's cache)."""
    page = ctx.new_page()
    cdp = ctx.new_cdp_session(page)
    cdp.send("Network.enable")
    urls: dict[str, str] = {}
    sizes: dict[str, int] = {}
    cdp.on(
        "Network.requestWillBeSent", lambda e: urls.__setitem__(e["requestId"], e["request"]["url"])
    )
    cdp.on(
        "Network.loadingFinished",
        lambda e: sizes.__setitem__(
            urls.get(e["requestId"], e["requestId"]),
            sizes.get(urls.get(e["requestId"], ""), 0) + int(e["encodedDataLength"]),
        ),
    )
    page.goto(url)
    _settled(page)
    page.close()
    return sizes


def test_the_catalog_draws_every_scene_from_one_request(server, fresh):
    page = fresh.new_page()
    api: list[str] = []
    page.on("request", lambda r: "/api/" in r.url and api.append(r.url))
    page.goto(f"{server}/")
    page.wait_for_function(
        "() => [...document.querySelectorAll('svg[data-thumb]')]"
        ".every(s => ['1', 'error'].includes(s.dataset.ready))",  # not 'waiting'
        timeout=90_000,
    )
    ready = page.eval_on_selector_all("svg[data-thumb]", "els => els.map(e => e.dataset.ready)")
    assert ready and set(ready) == {"1"}  # every scene drawn, none failed
    assert api == [f"{server}/api/v1/scenes/catalog"]


@pytest.mark.parametrize("scene", ["double_pendulum", "spherical_pendulum"])
def test_pause_is_never_shown_over_a_blank_canvas(server, fresh, scene):
    fresh.add_init_script(BLANK_PROBE)
    page = fresh.new_page()
    page.goto(f"{server}/scenes/{scene}")
    _settled(page)
    seen = page.evaluate("() => window.__blank")
    assert seen["checked"] > 0
    assert seen["pause_over_blank"] == 0, seen


def _scene_bytes(server, fresh, scene) -> tuple[dict, dict]:
    url = f"{server}/scenes/{scene}"
    warm = fresh.new_page()  # the connection opened, not counted with the page
    warm.goto(f"{server}/healthz")
    warm.close()
    cold = _visit(fresh, url)
    repeat = _visit(fresh, url)
    print(
        f"{scene}: cold {sum(cold.values()) / 1000:.0f} kB in {len(cold)} requests, "
        f"repeat {sum(repeat.values()) / 1000:.1f} kB in {len(repeat)} requests",
        "largest repeat:",
        sorted(((v, k.rsplit("/", 3)[-1]) for k, v in repeat.items()), reverse=True)[:4],
    )
    return cold, repeat


@pytest.mark.parametrize("scene", ["double_pendulum", "rolling_disk"])
def test_a_scene_page_transfers_at_most_1_5_mb_cold(server, fresh, scene):
    cold, repeat = _scene_bytes(server, fresh, scene)
    assert sum(cold.values()) <= COLD_LIMIT
    # a repeat visit fetches no static file again: every one is cached under its versioned URL
    assert [u for u, n in repeat.items() if "/static/" in u and n > 0] == []
    # ... and, but for the server's run of the motion, stays far under 100 kB
    assert sum(v for u, v in repeat.items() if "/api/v1/simulate" not in u) <= REPEAT_LIMIT / 4


@pytest.mark.parametrize("scene", ["double_pendulum", "spherical_pendulum"])
def test_a_repeat_visit_transfers_at_most_100_kb(server, fresh, scene):
    """The server's run is the one thing a repeat visit must fetch again: asked for at 30 samples
    a second (drawn at 60 by interpolation), a double pendulum's 10 s is ~55 kB gzipped."""
    _, repeat = _scene_bytes(server, fresh, scene)
    assert sum(repeat.values()) <= REPEAT_LIMIT


#: Records, as each derivation step is typeset, which step and whether the reader could see it.
#: With `scroll`, the moment the steps are on the page the last one is scrolled into view, before
#: anything is typeset (the page holds MathJax until its animation moves).
ORDER_PROBE = """
(scroll) => {
  window.__typeset = [];
  const seen = new Set();
  new MutationObserver(() => {
    const steps = [...document.querySelectorAll('#steps li.step')];
    if (scroll && steps.length && !window.__scrolled) {
      window.__scrolled = true;
      steps[steps.length - 1].scrollIntoView({ block: 'start' });
    }
    for (const li of steps) {
      if (li.dataset.typeset === '1' && !seen.has(li)) {
        seen.add(li);
        const r = li.getBoundingClientRect();
        const visible = r.height > 0 && r.bottom > 0 && r.top < innerHeight;
        window.__typeset.push([li.dataset.step, visible]);
      }
    }
  }).observe(document, { subtree: true, childList: true, attributes: true,
                         attributeFilter: ['data-typeset'] });
}
"""


def test_the_steps_a_reader_looks_at_are_typeset_first(server, fresh):
    """A student who goes straight to the end of the derivation gets the Euler–Lagrange
    equations typeset first, not after the free-body diagram they scrolled past. The order
    matters where MathJax typesets the steps live (a posted system, or a ready-made file that
    did not come): the file is held back here."""
    fresh.add_init_script(f"({ORDER_PROBE})(true)")
    fresh.route("**/math/*.json", lambda route: route.abort())
    page = fresh.new_page()
    page.goto(f"{server}/scenes/double_pendulum")
    _settled(page)
    order = page.evaluate("() => window.__typeset")
    ids = page.eval_on_selector_all("#steps li.step", "els => els.map((e) => e.dataset.step)")
    assert sorted(s for s, _ in order) == sorted(ids)  # every step, once
    # those in view (the end of the derivation, where the page scrolled to) first, then the rest
    in_view = [visible for _, visible in order]
    # with the math ready-made a step takes milliseconds, and the steps' heights change as each
    # batch goes up, so the observer's report may lag one batch: two steps out of view may slip
    # in before the last ones in view (seen: lagrange, fbd, coordinates, matrix, conserved), but
    # the first is in view and every step in view is up within two places of its turn
    assert in_view[0], order
    seen = [k for k, visible in enumerate(in_view) if visible]
    assert seen[-1] < len(seen) + 2, order
    first = [s for s, visible in order if visible]
    assert ids[-1] in first and ids[0] not in first, order


#: Counts the observer's callbacks in which steps were marked typeset.
BATCH_PROBE = """
(() => {
  window.__batches = [];
  const seen = new Set();
  new MutationObserver(() => {
    const now = [...document.querySelectorAll('#steps li.step')]
      .filter((li) => li.dataset.typeset === '1' && !seen.has(li));
    now.forEach((li) => seen.add(li));
    if (now.length) window.__batches.push(now.map((li) => li.dataset.step));
  }).observe(document, { subtree: true, attributes: true, attributeFilter: ['data-typeset'] });
})();
"""


def test_ready_made_math_goes_up_in_one_go_without_waiting_for_the_motion(server, fresh):
    """With the math typeset ahead of time, a step costs only its insertion: the whole
    derivation goes up in one task (no step half a second behind the others), and it does not
    wait for the animation to move, which once put it 0.3 s past the 1.0 s target."""
    fresh.add_init_script(BATCH_PROBE)
    page = fresh.new_page()
    # The motion held back: no server run, no preview, and the page's clock stopped, so the
    # motion never comes and the page's deadline for it (a timer) never fires. A derivation
    # that waited for either would never be typeset.
    page.route("**/api/v1/simulate", lambda route: None)  # never answered
    page.route("**/scenes/*/live.js*", lambda route: None)
    page.clock.install()
    page.clock.pause_at(time.time() + 1)  # (a second ahead: it cannot go back)
    page.goto(f"{server}/scenes/double_pendulum", wait_until="commit")  # (no load event)
    page.wait_for_selector("#steps[data-typeset='1']", state="attached", timeout=60_000)
    assert page.evaluate("() => document.querySelector('#canvas').dataset.frame") is None
    ids = page.eval_on_selector_all("#steps li.step", "els => els.map((e) => e.dataset.step)")
    batches = page.evaluate("() => window.__batches")
    assert len(batches) == 1 and sorted(batches[0]) == sorted(ids), batches
    # every formula ready-made: none of them is a MathJax typeset of this visit
    assert page.evaluate("() => document.querySelector('#steps mjx-container') !== null")
    assert page.evaluate(
        "() => [...document.querySelectorAll('#steps .math, #steps .text')]"
        ".every((el) => !/\\\\[\\[(]/.test(el.textContent))"
    )


def test_a_link_to_the_derivation_keeps_its_place_and_typesets_what_it_shows(server, fresh):
    """The page rewrites its URL as controls change; a #fragment (a link to the derivation, the
    skip link's target) must survive that, and the steps it shows come first."""
    fresh.add_init_script(f"({ORDER_PROBE})(false)")
    page = fresh.new_page()
    page.goto(f"{server}/scenes/simple_pendulum#h-derivation")
    _settled(page)
    assert page.evaluate("() => location.hash") == "#h-derivation"
    assert (
        page.evaluate("() => document.querySelector('#h-derivation').getBoundingClientRect().top")
        < 200
    )
    order = page.evaluate("() => window.__typeset")
    in_view = [visible for _, visible in order]
    # those the reader sees, then the rest: no step in view waits behind one out of view
    assert in_view[0] and in_view == sorted(in_view, reverse=True), order
