"""Lecture mode as an instructor on a projector needs it (instructor play-test): ← from a step
shows the step before from its title, the step counter is always in view, a link's step opens
there and the address follows the steps, text is legible from the back of a hall (≥ 24 px: the
canvas, the free-body diagram, the energy bars), plots name coordinates as symbols, the answer
field is as wide as its row, the work table fits a phone, the paused free-body diagram shows the
clock's instant, and the period and the work table's rows are worded for this page."""

from __future__ import annotations

import contextlib
import re

import pytest
from lecture_keys import press, reveal_all

pytestmark = pytest.mark.browser

HALL_PX = 24  # the least text size read from the back of a lecture hall

#: The current step's title against the sticky header, and the counter.
PLACE = """() => {
  const header = document.querySelector('body > header').getBoundingClientRect();
  const step = document.querySelector('#steps > .step.current');
  const title = step.querySelector('h3').getBoundingClientRect();
  return { header: header.bottom, top: step.getBoundingClientRect().top, titleTop: title.top,
           titleBottom: title.bottom,
           step: step.dataset.step, counter: document.querySelector('#step-counter').innerText };
}"""

#: Where the counter is and whether it is what the screen shows at its centre (not covered).
COUNTER = """() => {
  const c = document.querySelector('#step-counter');
  const r = c.getBoundingClientRect();
  const hit = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
  return { top: r.top, bottom: r.bottom, height: r.height, left: r.left, right: r.right,
           seen: Boolean(hit && c.contains(hit)), font: parseFloat(getComputedStyle(c).fontSize) };
}"""


@contextlib.contextmanager
def projector(browser, width: int, height: int, init_script: str | None = None):
    """A page of its own at a projector's (or a phone's) size, and the errors it throws."""
    ctx = browser.new_context(viewport={"width": width, "height": height}, bypass_csp=True)
    try:
        page = ctx.new_page()
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        if init_script:
            page.add_init_script(init_script)
        yield page, errors
    finally:
        ctx.close()


def open_lecture(p, url: str) -> None:
    p.goto(url)
    p.wait_for_selector("#steps[data-typeset='1']", state="attached", timeout=90_000)
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    p.wait_for_timeout(300)


def steps_of(p) -> list[str]:
    return p.eval_on_selector_all("#steps > .step", "s => s.map(x => x.dataset.step)")


@pytest.mark.parametrize(
    "scene,size", [("simple_pendulum", (1024, 768)), ("double_pendulum", (1280, 720))]
)
def test_back_from_the_last_step_shows_the_step_before_from_its_title(server, browser, scene, size):
    with projector(browser, *size) as (p, errors):
        open_lecture(p, f"{server}/scenes/{scene}?lecture=1")
        ids = steps_of(p)
        reveal_all(p)
        press(p, "ArrowLeft")
        at = p.evaluate(PLACE)
        n = len(ids)
        assert at["counter"].startswith(f"step {n - 1} of {n}")
        assert at["step"] == ids[n - 2]
        # its title whole, just under the sticky header (it ended at y = 76 under a 68 px header)
        assert at["header"] - 1 <= at["top"] <= at["header"] + HALL_PX, at
        assert at["titleTop"] >= at["header"], at
        assert at["titleBottom"] <= size[1]
        assert errors == []


@pytest.mark.parametrize("size", [(1024, 768), (1280, 720), (1920, 1080), (390, 844)])
def test_the_step_counter_is_always_in_view(server, browser, size):
    with projector(browser, *size) as (p, errors):
        open_lecture(p, f"{server}/scenes/atwood_machine?lecture=1")
        for k in range(8):
            c = p.evaluate(COUNTER)
            assert c["height"] > 0 and c["top"] >= 0 and c["bottom"] <= size[1], (k, c)
            assert c["left"] >= 0 and c["right"] <= size[0], (k, c)
            assert c["seen"], (k, c)  # nothing covers it
            assert c["font"] >= HALL_PX
            press(p, "ArrowRight")
        assert p.evaluate("scrollY") > size[1]  # it stayed while the page moved on
        assert p.evaluate("document.documentElement.scrollWidth") <= size[0]
        assert errors == []


def test_a_linked_step_opens_there_and_the_address_follows_the_steps(server, browser):
    with projector(browser, 1280, 720) as (p, errors):
        open_lecture(p, f"{server}/scenes/atwood_machine?lecture=1&step=4")
        ids = steps_of(p)
        # the fourth step (step=4 counts from 1, as the header does), its title under the header
        # once the math above it is typeset
        p.wait_for_function(
            f"""() => {{ const at = ({PLACE})();
                return at.top >= at.header - 1 && at.top <= at.header + {HALL_PX}; }}""",
            timeout=30_000,
        )
        at = p.evaluate(PLACE)
        assert at["step"] == ids[3] and at["counter"].startswith(f"step 4 of {len(ids)}")
        assert p.get_attribute("#steps", "data-revealed") == "4"
        # → goes on from there (it paged through steps 1 to 3 first)
        for _ in range(10):
            press(p, "ArrowRight")
            if p.get_attribute("#steps", "data-revealed") == "5":
                break
        assert p.evaluate(PLACE)["step"] == ids[4]
        assert "step=5" in p.evaluate("location.search")  # the address keeps the place
        press(p, "ArrowLeft")
        assert "step=4" in p.evaluate("location.search")
        assert errors == []


# Every canvas text with its font, as drawn (the canvas cannot be asked afterwards).
RECORD_CANVAS_TEXT = """
(() => {
  const fill = CanvasRenderingContext2D.prototype.fillText;
  window.__canvasText = {};
  CanvasRenderingContext2D.prototype.fillText = function (text, ...rest) {
    if (this.canvas.id === 'canvas') window.__canvasText[text] = this.font;
    return fill.call(this, text, ...rest);
  };
})();
"""

#: On-screen px of each text of an svg drawn in its own units (the FBD, the energy bars).
SVG_TEXT_PX = """(svg) => {
  const k = svg.getBoundingClientRect().width / svg.viewBox.baseVal.width;
  return [...svg.querySelectorAll('text')].filter((t) => t.textContent.trim())
    .map((t) => [t.textContent, parseFloat(getComputedStyle(t).fontSize) * k]);
}"""


def test_labels_are_legible_from_the_back_of_the_hall(server, browser):
    with projector(browser, 1024, 768, RECORD_CANVAS_TEXT) as (p, errors):
        open_lecture(p, f"{server}/scenes/simple_pendulum?lecture=1")
        p.keyboard.press("p")  # paused: the free-body diagram drawn at the instant shown
        p.evaluate("window.__canvasText = {}")  # what a frame draws now, not the wait message
        p.wait_for_timeout(300)
        drawn = p.evaluate("window.__canvasText")
        # canvas px drawn, times the canvas's on-screen scale (a short screen may shrink it)
        scale = p.evaluate(
            """() => { const c = document.querySelector('#canvas');
                return Math.min(c.clientWidth / (c.width / devicePixelRatio),
                                c.clientHeight / (c.height / devicePixelRatio)); }"""
        )
        px = lambda font: float(re.search(r"([\d.]+)px", font).group(1)) * scale  # noqa: E731
        assert "bob" in drawn and any(t.endswith("cm") or t.endswith(" m") for t in drawn)
        for text, font in drawn.items():
            assert px(font) >= HALL_PX, (text, font, scale)
        fbd = p.evaluate(SVG_TEXT_PX, p.locator("#fbd-svg").element_handle())
        assert any(t.startswith("t = ") for t, _ in fbd) and any(t == "bob" for t, _ in fbd)
        for text, size in fbd:
            assert size >= HALL_PX - 0.1, (text, size)
        bars = p.evaluate(SVG_TEXT_PX, p.locator("#instruments svg").element_handle())
        assert {"T", "E′"} <= {t for t, _ in bars}
        for text, size in bars:
            assert size >= HALL_PX - 0.1, (text, size)
        # the plots name the coordinate as the page does: θ and θ̇, not theta and theta_dot
        p.wait_for_selector("#plot-phase .main-svg", state="attached", timeout=60_000)
        words = p.eval_on_selector_all(
            "#plot-phase text, #plot-q text", "ts => ts.map(t => t.textContent).join(' | ')"
        )
        assert "phase portrait of θ" in words and "θ\u0307 (rad/s)" in words, words
        assert "theta" not in words
        assert errors == []


def test_the_answer_field_takes_the_row(server, browser):
    with projector(browser, 1024, 768) as (p, errors):
        open_lecture(p, f"{server}/scenes/simple_pendulum?lecture=1&step=4")
        box = p.locator("li[data-step='energy'] details.yourturn").first
        box.locator("summary").click()
        widths = p.evaluate(
            """(b) => ({ input: b.querySelector('input').getBoundingClientRect().width,
                         row: b.querySelector('.row').getBoundingClientRect().width })""",
            box.element_handle(),
        )
        # it was ~90 px: "1/2 m" of "1/2 m l^2 theta'^2" in view
        assert widths["input"] >= 0.95 * widths["row"] and widths["input"] > 300, widths
        assert errors == []


def test_the_work_table_fits_a_phone_or_scrolls_in_its_box(server, browser):
    with projector(browser, 390, 844) as (p, errors):
        open_lecture(p, f"{server}/scenes/spring_mass_damper?lecture=1")
        p.wait_for_function("document.querySelector('#work-table').dataset.gap !== undefined")
        p.evaluate("document.querySelector('#work-panel details.fold').open = true")
        p.locator("#work-table").scroll_into_view_if_needed()
        p.wait_for_timeout(300)
        got = p.evaluate(
            """() => { const t = document.querySelector('#work-table');
              const box = t.parentElement, cue = document.querySelector('#work-panel .scroll-cue');
              return { page: document.documentElement.scrollWidth,
                       table: t.getBoundingClientRect().width, box: box.clientWidth,
                       scrolls: getComputedStyle(box).overflowX,
                       cue: cue ? getComputedStyle(cue).display : null,
                       cueText: cue ? cue.textContent : '' }; }"""
        )
        assert got["page"] <= 390, got  # the page itself is never wider than the phone (444)
        if got["table"] > got["box"] + 1:  # wider than its box: it scrolls there, and says so
            assert got["scrolls"] == "auto" and got["cue"] != "none" and "scroll" in got["cueText"]
        assert errors == []


def fbd_time(p) -> str:
    return p.eval_on_selector_all(
        "#fbd-svg text", "ts => ts.map(t => t.textContent).find(x => x.startsWith('t = '))"
    )


def test_the_paused_free_body_diagram_shows_the_clocks_instant(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum?t_end=10")
    for wait in (230, 370, 110, 290, 170, 410):  # paused at whatever frame the animation is on
        p.click("#play")
        p.wait_for_timeout(wait)
        p.click("#play")
        p.wait_for_timeout(120)
        assert fbd_time(p) == p.inner_text("#clock"), wait
    for key in (".", ".", ",", "."):  # single steps too
        p.keyboard.press(key)
        p.wait_for_timeout(150)
        assert fbd_time(p) == p.inner_text("#clock"), key
    # a new run on another grid of samples (rk4 at dt = 0.05 s: 20 a second) while paused
    run = p.get_attribute("#canvas", "data-run")
    p.select_option("#method", "rk4")
    p.select_option("#dt", "0.05")
    p.wait_for_function(
        "(n) => document.querySelector('#canvas').dataset.run !== n", arg=run, timeout=60_000
    )
    page.settle()
    p.wait_for_timeout(200)
    assert fbd_time(p) == p.inner_text("#clock")
    p.select_option("#method", "dop853_c")  # the session page's next test gets the default
    page.settle()
    assert page.errors == []


def test_the_period_is_not_called_t_and_no_number_reads_minus_zero(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum?t_end=10")
    p.eval_on_selector("#scrub", "s => { s.value = 1000; s.dispatchEvent(new Event('input')); }")
    p.wait_for_function("document.querySelector('#period').dataset.period")
    shown = p.inner_text("#period")
    assert shown.startswith("period ≈ ") and "T" not in shown  # T is the kinetic energy here
    # a mean that rounds to zero prints as 0.000, whatever its sign
    got = p.evaluate(
        """async () => { const { fixed } = await import(
              document.querySelector('script[type=module][src*="page.js"]').src
                .replace('page.js', 'instruments.js'));
            return [fixed(-0.00004, 3), fixed(-0.0004, 3), fixed(-0.0006, 3), fixed(0, 2),
                    fixed(-1e-9, 0)]; }"""
    )
    assert got == ["0.000", "0.000", "-0.001", "0.00", "0"]
    assert "-0.000" not in p.inner_text("#instruments")
    assert page.errors == []


def test_the_work_table_names_a_force_and_its_kind(server, page):
    p = page.page
    p.goto(f"{server}/scenes/spring_mass_damper")
    p.wait_for_function(
        "document.querySelector('#work-table').dataset.gap !== undefined", timeout=90_000
    )
    rows = p.eval_on_selector_all(
        "#work-table tr td:first-child", "tds => tds.map(td => td.textContent)"
    )
    # the spec's force is named "drive": not "force drive" (which reads as an order)
    assert "drive (applied force)" in rows and "force drive" not in rows, rows
    assert "spring" in rows and "damper" in rows
    page.settle()
    assert page.errors == []
