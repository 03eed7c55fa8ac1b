"""Lecture mode, live (issue 26, item 2): the instructor changes a parameter and plays or pauses
beside the step being read, the 3-D canvas is not covered by its drag hint, and no equation is
shrunk below the room's 24 px.

- A control strip (play/pause and the scene's parameters) stays on the screen beside a step
  revealed far down the derivation (it was ~1300 px away, in the Parameters panel); a value typed
  into it is the panel's value, the run's and the address's.
- The hint is a line under the canvas: nothing is written over the motion (a 3-D hint covered
  about a third of a 374×247 canvas at 1024×768), and in lecture mode it goes after the canvas
  was used.
- Every equation of every step in lecture mode is at least 24 px: broken into lines, never
  scaled down (49 of 202 lecture screens showed 19.7 px).
"""

from __future__ import annotations

import pytest
from lecture_keys import press, reveal_all
from test_lecture_hall import open_lecture, projector

pytestmark = pytest.mark.browser

HALL_PX = 24

#: Where the strip's inputs are, and whether each is what the screen shows at its centre.
STRIP = """() => {
  const strip = document.getElementById('lecture-strip');
  if (!strip || strip.hidden) return null;
  const items = [...strip.querySelectorAll('button, input')].map((e) => {
    const r = e.getBoundingClientRect();
    const hit = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
    return { id: e.id, top: r.top, bottom: r.bottom, seen: hit === e || e.contains(hit),
             font: parseFloat(getComputedStyle(e).fontSize) };
  });
  return { items, height: innerHeight };
}"""

#: The smallest on-screen size (px) of a shown equation in the steps, and the scaled ones.
EQUATION_PX = """() => {
  let least = 1e9; const scaled = [];
  for (const box of document.querySelectorAll('#steps .math')) {
    const m = box.querySelector('mjx-container');
    if (!m || box.offsetParent === null) continue;
    const zoom = box.classList.contains('scaled')
      ? parseFloat(getComputedStyle(box).getPropertyValue('--fit-scale')) || 1 : 1;
    const px = parseFloat(getComputedStyle(m).fontSize) * zoom;
    least = Math.min(least, px);
    if (zoom < 1) scaled.push(box.dataset.latex.slice(0, 50));
  }
  return { least, scaled };
}"""

FITTED = """() => [...document.querySelectorAll('#steps .math')]
  .filter((m) => m.offsetParent !== null && m.querySelector('mjx-container'))
  .every((m) => m.dataset.fitWidth === String(m.clientWidth) && m.dataset.fitMode === 'lecture')"""


@pytest.mark.parametrize("size", [(1024, 768), (1280, 720), (1366, 768), (1920, 1080)])
def test_the_strip_is_beside_a_step_far_down_and_drives_the_run(server, browser, artifacts, size):
    with projector(browser, *size) as (p, errors):
        open_lecture(p, f"{server}/scenes/double_pendulum?lecture=1")
        for _ in range(4):  # well into the derivation: the page scrolled far from the panel
            press(p, "ArrowRight")
        assert p.evaluate("scrollY") > 600
        strip = p.evaluate(STRIP)
        assert strip is not None, "no control strip in lecture mode"
        ids = {i["id"] for i in strip["items"]}
        assert {"strip-play", "strip-n-l2", "strip-s-l2", "strip-n-m1", "strip-n-g"} <= ids
        for item in strip["items"]:  # on the screen, uncovered, read from the back of the hall
            assert 0 <= item["top"] and item["bottom"] <= strip["height"], item
            assert item["seen"], item
            assert item["font"] >= HALL_PX, item
        p.screenshot(path=str(artifacts / f"lecture_strip_{size[0]}x{size[1]}.png"))
        # a value typed in the strip is the panel's, the address's and the run's
        runs = p.get_attribute("#canvas", "data-run")
        p.fill("#strip-n-l2", "1.5")
        p.press("#strip-n-l2", "Enter")
        p.wait_for_function("document.getElementById('n-l2').value === '1.5'")
        p.wait_for_function("new URLSearchParams(location.search).get('l2') === '1.5'")
        p.wait_for_function(
            f"document.querySelector('#canvas').dataset.run !== '{runs}'", timeout=60_000
        )
        # its play button is the page's: pauses and plays
        before = p.get_attribute("#play", "aria-pressed")
        p.click("#strip-play")
        assert p.get_attribute("#play", "aria-pressed") != before
        assert p.get_attribute("#strip-play", "aria-pressed") == p.get_attribute(
            "#play", "aria-pressed"
        )
        # the panel's value set from elsewhere (Reset) is shown in the strip too
        p.evaluate("document.getElementById('reset').click()")
        p.wait_for_function("document.getElementById('strip-n-l2').value === '1'")
        assert errors == []


def test_no_strip_outside_lecture_mode(server, browser):
    with projector(browser, 1280, 720) as (p, errors):
        open_lecture(p, f"{server}/scenes/double_pendulum")
        assert p.evaluate(STRIP) is None
        p.click("#lecture-toggle")
        assert p.evaluate(STRIP) is not None
        assert errors == []


@pytest.mark.parametrize("size", [(1024, 768), (1280, 720)])
def test_the_3d_hint_is_under_the_canvas_not_over_the_motion(server, browser, artifacts, size):
    with projector(browser, *size) as (p, errors):
        open_lecture(p, f"{server}/scenes/spherical_pendulum?lecture=1")
        canvas = p.locator("#canvas").bounding_box()
        hint = p.locator("#canvas-hint")
        assert "turn the view" in hint.inner_text()
        box = hint.bounding_box()
        assert box["y"] >= canvas["y"] + canvas["height"] - 1, (box, canvas)  # below, not over
        p.screenshot(path=str(artifacts / f"lecture_3d_hint_{size[0]}x{size[1]}.png"))
        # used once, the room gets the room back
        p.focus("#canvas")
        p.keyboard.press("Shift+ArrowLeft")
        assert not hint.is_visible()
        assert errors == []


@pytest.mark.timeout(600)
@pytest.mark.parametrize("scene", ["double_pendulum", "cart_pendulum", "elastic_pendulum"])
def test_lecture_equations_are_never_shrunk_below_24_px(server, browser, scene):
    for size in [(1024, 768), (1280, 720)]:
        with projector(browser, *size) as (p, errors):
            open_lecture(p, f"{server}/scenes/{scene}?lecture=1")
            reveal_all(p)
            p.wait_for_function(FITTED, timeout=60_000)
            got = p.evaluate(EQUATION_PX)
            assert got["scaled"] == [], f"{scene} at {size}: scaled down: {got['scaled']}"
            assert got["least"] >= HALL_PX, f"{scene} at {size}: {got}"
            assert errors == []
