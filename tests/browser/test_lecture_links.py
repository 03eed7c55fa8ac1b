"""Lecture-mode links and prose as the student play-test (round 2) found them: ?step=99 showed
"step 8 of 8" while the address kept step=99 (step=-3 and step=abc were set to 0), and at
1024×768 the "." after the mass-matrix sentence's math wrapped to the start of the next line."""

from __future__ import annotations

import re

import pytest
from test_lecture_hall import open_lecture, projector, steps_of

pytestmark = pytest.mark.browser


def address_step(p) -> str | None:
    found = re.search(r"[?&]step=([^&]*)", p.evaluate("location.search"))
    return found.group(1) if found else None


@pytest.mark.parametrize(
    "asked,shown",
    # step= counts from 1, as the header does ("step 3 of 8" is step=3); an old link's step=0
    # (they counted from 0) is the first
    [("99", "last"), ("-3", 0), ("abc", 0), ("3", 2), ("0", 0)],
)
def test_the_address_says_the_step_shown(server, browser, asked, shown):
    with projector(browser, 1280, 720) as (p, errors):
        open_lecture(p, f"{server}/scenes/atwood_machine?lecture=1&step={asked}")
        n = len(steps_of(p))
        index = n - 1 if shown == "last" else shown
        # the page shows step index + 1 (counted from 1), and the address says the same step
        assert p.get_attribute("#steps", "data-revealed") == str(index + 1)
        assert p.inner_text("#step-counter").startswith(f"step {index + 1} of {n}")
        assert address_step(p) == str(index + 1)
        assert errors == []


#: Each inline math in a step's prose followed by punctuation: is the punctuation on the math's
#: line, right after it (not at the start of the next line)?
PUNCTUATION_AFTER_MATH = r"""() => {
  const out = [];
  const prose = "#steps > .step:not(.hidden) :is(p.text, p.note)";
  const maths = document.querySelectorAll(`${prose} mjx-container`);
  for (const m of maths) {
    let n = m;
    while (n && !n.nextSibling) n = n.parentNode;
    n = n && n.nextSibling;
    while (n && n.nodeType !== Node.TEXT_NODE) n = n.firstChild || n.nextSibling;
    if (!n || !/^[.,;:!?)]/.test(n.textContent)) continue;
    const r = document.createRange();
    r.setStart(n, 0);
    r.setEnd(n, 1);
    const mark = r.getBoundingClientRect(), math = m.getBoundingClientRect();
    out.push({ mark: n.textContent[0], sameLine: mark.top < math.bottom && mark.bottom > math.top,
               after: mark.left >= math.right - 2, math: m.getAttribute('aria-label') || '' });
  }
  return out;
}"""


@pytest.mark.timeout(300)  # 36 widths, each refitting the equations: ~40 s quiet, 180 s at load 16
def test_punctuation_stays_with_the_math_before_it(server, browser):
    with projector(browser, 1024, 768) as (p, errors):
        open_lecture(p, f"{server}/scenes/double_pendulum?lecture=1&step=99")
        p.wait_for_timeout(500)
        checked = 0
        # the play-test's width, and a sweep around it: wherever a line happens to end
        for width in [1024, *range(961, 1280, 9)]:
            p.set_viewport_size({"width": width, "height": 768})
            p.wait_for_timeout(60)
            marks = p.evaluate(PUNCTUATION_AFTER_MATH)
            checked += len(marks)
            bad = [m for m in marks if not (m["sameLine"] and m["after"])]
            assert bad == [], (width, bad)
        assert checked > 0  # the derivation has such sentences (the mass matrix's "f(q, q̇, t).")
        assert errors == []


@pytest.mark.parametrize("scene", ["rolling_disk", "double_pendulum"])
def test_a_link_to_the_derivation_stays_there_while_the_page_fills_in(server, browser, scene):
    """The skip link's target, #h-derivation: the plots and panels above it arrive later and
    pushed the heading a screen down (rolling disk, 1280×800). Once everything has arrived the
    heading is still at the top, under the sticky header; a reader who scrolls is left alone."""
    with projector(browser, 1280, 800) as (p, errors):
        p.goto(f"{server}/scenes/{scene}#h-derivation")
        open_lecture(p, p.url)
        p.wait_for_function("() => document.querySelector('#plot-q .modebar-btn')", timeout=90_000)
        p.wait_for_timeout(500)
        top = p.evaluate("document.getElementById('h-derivation').getBoundingClientRect().top")
        pad = p.evaluate("parseFloat(getComputedStyle(document.documentElement).scrollPaddingTop)")
        header = p.evaluate("document.querySelector('body > header').offsetHeight")
        assert header <= top <= pad + 40, (top, pad, header)
        # the reader scrolls away: the page does not pull them back
        p.mouse.wheel(0, 600)
        p.wait_for_timeout(400)
        p.evaluate("window.dispatchEvent(new Event('resize'))")
        p.wait_for_timeout(400)
        moved = p.evaluate("document.getElementById('h-derivation').getBoundingClientRect().top")
        assert moved < top - 300
        assert errors == []
