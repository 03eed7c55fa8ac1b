"""Lecture mode on a projector (student play-test): → / space / PageDown page through a step
taller than the screen before revealing the next, so every equation of the derivation is on the
screen at some press; the counter says when more of the step lies below; a refused run says
'no run' on the play button, and the line under the canvas stays short enough to keep the
controls on a 1280×720 screen."""

from __future__ import annotations

import pytest
from lecture_keys import press

pytestmark = pytest.mark.browser

#: Which equation lines (by index in the whole derivation) are wholly on screen, below the header.
SEEN = """() => {
  const top = document.querySelector('body > header').getBoundingClientRect().bottom;
  const lines = [...document.querySelectorAll('#steps .math-line')];
  return lines.map((l, i) => {
    const r = l.getBoundingClientRect();
    return r.height > 0 && r.top >= top - 1 && r.bottom <= innerHeight + 1 ? i : -1;
  }).filter((i) => i >= 0);
}"""


#: The current step runs on below the screen.
TALLER_THAN_SCREEN = """() => {
  const top = document.querySelector('body > header').getBoundingClientRect().bottom;
  const r = document.querySelector('#steps > .step.current').getBoundingClientRect();
  return r.height > innerHeight - top;
}"""


@pytest.mark.parametrize("size", [(1280, 720), (1024, 768)])
def test_the_arrow_key_shows_every_equation_of_a_long_derivation(server, browser, size):
    ctx = browser.new_context(viewport={"width": size[0], "height": size[1]}, bypass_csp=True)
    try:
        p = ctx.new_page()
        p.goto(f"{server}/scenes/double_pendulum?lecture=1")
        p.wait_for_selector("#steps[data-typeset='1']", state="attached", timeout=90_000)
        p.wait_for_timeout(300)
        total = p.locator("#steps .math-line").count()
        steps = p.locator("#steps > li.step").count()
        seen: set[int] = set(p.evaluate(SEEN))
        more_said = False
        for _ in range(120):
            more_said |= "more below" in p.inner_text("#step-counter")
            if p.get_attribute("#steps", "data-revealed") == str(steps) and "more below" not in (
                p.inner_text("#step-counter")
            ):
                break
            press(p, "ArrowRight")
            seen |= set(p.evaluate(SEEN))
        missed = sorted(set(range(total)) - seen)
        assert not missed, f"{len(missed)} of {total} equation lines never on screen: {missed}"
        assert more_said  # its Euler–Lagrange step is taller than the screen
        # ← hides the steps again, the step before coming back from its title; a long one paged
        # into with → is paged back up with ← before it is hidden
        paged_back = False
        for _ in range(120):
            revealed = p.get_attribute("#steps", "data-revealed")
            if revealed == "1":
                break
            press(p, "ArrowLeft")
            if p.evaluate(TALLER_THAN_SCREEN):
                press(p, "ArrowRight")  # the next screen of it (the next step stays hidden)
                y = p.evaluate("scrollY")
                press(p, "ArrowLeft")
                same = p.get_attribute("#steps", "data-revealed") == str(int(revealed) - 1)
                paged_back |= same and p.evaluate("scrollY") < y
        assert p.get_attribute("#steps", "data-revealed") == "1"
        assert paged_back
    finally:
        ctx.close()


def test_a_refused_first_run_says_no_run_and_the_lecture_line_is_short(server, browser):
    ctx = browser.new_context(viewport={"width": 1280, "height": 720}, bypass_csp=True)
    try:
        p = ctx.new_page()
        p.goto(f"{server}/scenes/simple_pendulum?lecture=1")
        p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=60_000)
        badge = p.locator("#live-badge")
        assert badge.inner_text().startswith("server run (") and "samples/s" not in (
            badge.inner_text()
        )
        assert "samples/s" in badge.get_attribute("title")  # the full line, on hover
        # the play button on the screen: since issue 26 (item 2) the lecture strip's, right under
        # the animation (the playback row's own may lie below, in the column's scroll)
        controls = p.locator("#strip-play").bounding_box()
        assert controls["y"] + controls["height"] <= 720
        p.goto(f"{server}/scenes/simple_pendulum?m=0")
        p.wait_for_function("document.querySelector('#canvas').dataset.error", timeout=60_000)
        p.wait_for_function("document.querySelector('#play').textContent === 'no run'")
    finally:
        ctx.close()
