"""Keyboard and screen-reader access, checked by axe-core (bundled by axe-playwright-python) and by
walking the page with the keyboard.

- axe reports no serious or critical violation on the catalog, every scene page, lecture mode (all
  steps shown, at a projector's size) and the editor (empty, and with a derived scene);
- the first Tab of a page lands on the skip link, which moves focus to the content;
- plotly's toolbar buttons are out of the tab order; no cloud button is offered;
- MathJax's menu is on (speech and the explorer are one switch away) while its explorer and
  speech-rule engine are not loaded until switched on;
- an answer's verdict is inside a live region.
"""

from __future__ import annotations

import json
import urllib.request

import pytest
from lecture_keys import reveal_all

pytestmark = pytest.mark.browser

SERIOUS = {"serious", "critical"}


@pytest.fixture(scope="session")
def axe():
    from axe_playwright_python.sync_playwright import Axe

    return Axe()


def serious_violations(axe, p) -> list[str]:
    found = axe.run(p).response["violations"]
    return [
        f"{v['impact']} {v['id']}: {v['help']} at {[n['target'] for n in v['nodes'][:3]]}"
        for v in found
        if v["impact"] in SERIOUS
    ]


def open_scene(page, server: str, scene: str, query: str = "") -> None:
    page.page.goto(f"{server}/scenes/{scene}{query}")
    page.page.wait_for_function(
        "() => document.getElementById('steps').dataset.typeset === '1'", timeout=90_000
    )
    page.settle()
    page.page.wait_for_function("() => document.querySelector('#plot-q .modebar-btn')")


def scene_ids(server: str) -> list[str]:
    with urllib.request.urlopen(f"{server}/api/v1/scenes") as r:
        return [s["id"] for s in json.load(r)]


def test_axe_finds_nothing_serious_on_the_catalog_and_the_editor(server, page, axe):
    p = page.page
    p.goto(f"{server}/")
    p.wait_for_load_state("load")
    assert serious_violations(axe, p) == []
    p.goto(f"{server}/editor?from=simple_pendulum")
    p.wait_for_load_state("load")
    assert serious_violations(axe, p) == []
    p.click("#derive")
    p.wait_for_function(
        "() => document.getElementById('steps').dataset.typeset === '1'", timeout=90_000
    )
    page.settle()
    assert serious_violations(axe, p) == []


@pytest.mark.timeout(600)  # every built-in scene, one after another
def test_axe_finds_nothing_serious_on_any_scene_page(server, page, axe):
    for scene in scene_ids(server):
        open_scene(page, server, scene)
        found = serious_violations(axe, page.page)
        assert found == [], f"{scene}: {found}"


def test_axe_finds_nothing_serious_in_lecture_mode(server, page, sized, axe):
    p = page.page
    sized(1280, 720)
    open_scene(page, server, "double_pendulum", "?lecture=1")
    reveal_all(p)
    assert serious_violations(axe, p) == []


def test_first_tab_is_the_skip_link_and_toolbars_are_out_of_the_tab_order(server, page):
    p = page.page
    open_scene(page, server, "simple_pendulum")
    p.evaluate("document.activeElement && document.activeElement.blur()")
    p.keyboard.press("Tab")
    first = p.evaluate("[document.activeElement.className, document.activeElement.hash]")
    assert first == ["skip-link", "#main"]
    p.keyboard.press("Enter")
    assert p.evaluate("document.activeElement.id") == "main"
    buttons = p.evaluate(
        "[...document.querySelectorAll('.modebar-btn')].map((b) => b.getAttribute('tabindex'))"
    )
    assert buttons and set(buttons) == {"-1"}
    titles = p.evaluate(
        "[...document.querySelectorAll('.modebar-btn')].map((b) => b.dataset.title || '')"
    )
    assert not [t for t in titles if "share" in t.lower() or "cloud" in t.lower()]
    # nothing inside a plot is a tab stop: Tab goes from the controls to the derivation
    focusable = "a[href], button, input, select, summary, [tabindex]"
    stops = p.evaluate(
        f"""[...document.querySelectorAll('{focusable}')]
             .filter((e) => e.tabIndex >= 0 && e.offsetParent !== null && e.closest('.plot'))
             .length"""
    )
    assert stops == 0


def test_mathjax_menu_is_on_and_its_explorer_loads_only_on_demand(server, page):
    p = page.page
    open_scene(page, server, "simple_pendulum")
    assert p.evaluate("MathJax.config.options.enableMenu") is True
    # every equation can be reached to open the menu (speech, explorer) from the keyboard
    assert p.evaluate(
        "[...document.querySelectorAll('#steps mjx-container')].every((m) => m.tabIndex === 0)"
    )
    loaded = p.evaluate(
        "performance.getEntriesByType('resource').map((r) => r.name)"
        ".filter((n) => /a11y\\/(explorer|sre)|mathmaps/.test(n))"
    )
    assert loaded == []


def test_an_answers_verdict_is_announced(server, page):
    p = page.page
    open_scene(page, server, "simple_pendulum")
    box = p.locator('li[data-step="energy"] details.yourturn').first
    box.locator("summary").click()
    live = box.locator(".verdict").evaluate(
        "(v) => Boolean(v.closest('[aria-live=polite], [aria-live=assertive], [role=status]'))"
    )
    assert live
