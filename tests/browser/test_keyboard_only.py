"""The app without a mouse (WCAG 2.2 AA; issue 26, item 6): a keyboard alone walks the catalog,
a scene (play and pause, change a parameter, set a start, step through the derivation, check an
answer) and the editor. Only Tab, Shift+Tab, Enter, space, the arrows and typed text are used.

- every drag has a keyboard alternative (2.5.7): the focused canvas's arrow keys move the body
  (the start), Shift + arrows turn a 3-D view;
- the animation can be paused (2.2.2): space on the canvas, the play button, `p` anywhere, in or
  out of lecture mode;
- the canvas shows where the focus is (a visible ring);
- targets are at least 24 × 24 CSS px (2.5.8; math in a sentence is inline text, excepted);
- the ready-made math keeps its speech: each typeset equation carries assistive MathML.
"""

from __future__ import annotations

import pytest
from lecture_keys import press

pytestmark = pytest.mark.browser

ACTIVE = """() => { const a = document.activeElement;
  return a ? [a.tagName, a.id, a.className, a.getAttribute('data-scene') || ''] : null; }"""


def tab_to(p, test: str, *, back: bool = False, limit: int = 250) -> None:
    """Tab (or Shift+Tab) until document.activeElement satisfies the JS predicate `test`."""
    for _ in range(limit):
        if p.evaluate(f"(() => {{ const a = document.activeElement; return Boolean({test}); }})()"):
            return
        p.keyboard.press("Shift+Tab" if back else "Tab")
    raise AssertionError(
        f"{test} not reached by {'Shift+' if back else ''}Tab; at {p.evaluate(ACTIVE)}"
    )


def wait_scene(p) -> None:
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    p.wait_for_function("document.getElementById('steps').dataset.typeset === '1'", timeout=90_000)
    p.wait_for_function(
        "() => (document.documentElement.dataset.pending || '0') === '0'", timeout=60_000
    )


def test_a_keyboard_alone_walks_the_catalog_a_scene_and_the_editor(server, page, artifacts):
    p = page.page
    p.goto(f"{server}/")
    p.wait_for_load_state("load")
    # the catalog: Tab to a scene's card, Enter opens it
    tab_to(p, "a.dataset.scene === 'simple_pendulum'")
    p.keyboard.press("Enter")
    p.wait_for_url("**/scenes/simple_pendulum")
    wait_scene(p)

    # play / pause with the button
    tab_to(p, "a.id === 'play'")
    playing = p.get_attribute("#play", "aria-pressed")
    p.keyboard.press("Enter")
    assert p.get_attribute("#play", "aria-pressed") != playing
    p.keyboard.press("p")  # and p, outside lecture mode
    assert p.get_attribute("#play", "aria-pressed") == playing

    # the canvas: a tab stop with a visible ring; space pauses; arrows set a start (the drag's
    # keyboard alternative); the scene is then said in words
    tab_to(p, "a.id === 'canvas'")
    ring = p.evaluate(
        "(() => { const s = getComputedStyle(document.activeElement);"
        " return [s.outlineStyle, parseFloat(s.outlineWidth)]; })()"
    )
    assert ring[0] != "none" and ring[1] >= 2, ring
    if p.get_attribute("#play", "aria-pressed") == "true":
        p.keyboard.press(" ")
    assert p.get_attribute("#play", "aria-pressed") == "false"
    p.keyboard.press(" ")
    assert p.get_attribute("#play", "aria-pressed") == "true"
    theta = p.input_value("#n-theta")
    runs = p.get_attribute("#canvas", "data-run")
    for _ in range(3):
        p.keyboard.press("ArrowRight")
    p.wait_for_function(f"document.getElementById('n-theta').value !== {theta!r}")
    assert p.get_attribute("#play", "aria-pressed") == "false"  # held where the keys put it
    assert p.evaluate("scrollY") < 400  # the arrows moved the body, not the page
    p.wait_for_function(
        f"document.querySelector('#canvas').dataset.run !== {runs!r}", timeout=60_000
    )
    p.wait_for_function("document.getElementById('scene-description').textContent.includes('bob')")
    p.screenshot(path=str(artifacts / "keyboard_canvas_focus.png"))

    # a parameter typed into its box
    tab_to(p, "a.id === 'n-l'")
    p.keyboard.press("Control+A")
    p.keyboard.type("2")
    p.keyboard.press("Tab")
    p.wait_for_function("new URLSearchParams(location.search).get('l') === '2'")

    # the derivation step by step: the lecture toggle (in the header, Shift+Tab back to it)
    tab_to(p, "a.id === 'lecture-toggle'", back=True)
    p.keyboard.press("Enter")
    p.wait_for_function("document.body.classList.contains('lecture')")
    assert p.get_attribute("#steps", "data-revealed") == "1"
    for _ in range(6):
        press(p, "ArrowRight")
        if p.get_attribute("#steps", "data-revealed") != "1":
            break
    assert int(p.get_attribute("#steps", "data-revealed")) >= 2
    p.keyboard.press("p")  # p pauses in lecture mode too
    p.keyboard.press("Enter")  # the toggle still has the focus: leave lecture mode
    p.wait_for_function("!document.body.classList.contains('lecture')")

    # an answer checked: open "Your turn", type, Enter
    tab_to(p, "a.matches('li[data-step=\"energy\"] details.yourturn > summary')")
    p.keyboard.press("Enter")
    tab_to(p, "a.matches('li[data-step=\"energy\"] details.yourturn input')")
    p.keyboard.type("1/2 m l^2 theta'^2")
    p.keyboard.press("Enter")
    p.wait_for_function(
        "document.querySelector('li[data-step=\"energy\"] details.yourturn .verdict')"
        ".textContent.includes('Correct')",
        timeout=60_000,
    )

    # the editor: its text area lets Tab go on (no trap), and Derive works from the keyboard
    p.goto(f"{server}/editor?from=simple_pendulum")
    p.wait_for_function("document.getElementById('spec').value.includes('theta')")
    tab_to(p, "a.id === 'spec'")
    p.keyboard.press("Tab")
    assert p.evaluate("document.activeElement.id") != "spec"
    tab_to(p, "a.id === 'derive'")
    p.keyboard.press("Enter")
    p.wait_for_function(
        "() => document.getElementById('steps').dataset.typeset === '1'", timeout=90_000
    )
    page.settle()
    assert [e for e in page.errors if e.startswith("page error")] == []


#: Interactive elements smaller than 24 × 24 CSS px (2.5.8), bar those inline in a sentence.
SMALL_TARGETS = """() => [...document.querySelectorAll(
    'a[href], button, input, select, textarea, summary, canvas[tabindex]')]
  .filter((e) => e.offsetParent !== null && !e.closest('.modebar') && e.type !== 'hidden')
  .filter((e) => !(e.tagName === 'A' && e.closest('p, li, td, figcaption, caption')
                   && !e.closest('.cards')))
  .map((e) => { const r = e.getBoundingClientRect();
    return [e.tagName + '#' + e.id + '.' + e.className,
            Math.round(r.width), Math.round(r.height)]; })
  .filter(([, w, h]) => w > 0 && (w < 24 || h < 24))"""


@pytest.mark.parametrize("size", [(1280, 720), (390, 844)])
def test_targets_are_at_least_24_px(server, page, sized, size):
    p = page.page
    sized(*size)
    for path in ["/", "/scenes/double_pendulum", "/editor?from=simple_pendulum"]:
        p.goto(f"{server}{path}")
        if "scenes" in path:
            wait_scene(p)
        else:
            p.wait_for_load_state("load")
        assert p.evaluate(SMALL_TARGETS) == [], path
        page.settle()


def test_typeset_math_keeps_its_speech(server, page):
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    wait_scene(p)
    silent = p.evaluate(
        """[...document.querySelectorAll('#steps mjx-container')]
           .filter((m) => !m.querySelector('mjx-assistive-mml math')
                          && !m.getAttribute('aria-label'))
           .map((m) => m.dataset.tex || m.outerHTML.slice(0, 80))"""
    )
    assert p.evaluate("document.querySelectorAll('#steps mjx-container').length") > 50
    assert silent == []


def test_shift_arrows_turn_a_3d_view_from_the_keyboard(server, page):
    p = page.page
    p.goto(f"{server}/scenes/spherical_pendulum")
    wait_scene(p)
    p.focus("#canvas")
    yaw = p.evaluate("JSON.parse(document.getElementById('canvas').dataset.camera).yaw")
    p.keyboard.press("Shift+ArrowLeft")
    p.keyboard.press("Shift+ArrowLeft")
    after = p.evaluate("JSON.parse(document.getElementById('canvas').dataset.camera).yaw")
    assert after == pytest.approx(yaw - 0.24, abs=1e-9)
