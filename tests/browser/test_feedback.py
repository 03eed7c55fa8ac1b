"""Your-turn feedback and the equilibria panel show math (MathJax), never code, and each check
replaces the last one's result in a live region a screen reader announces."""

from __future__ import annotations

import pytest
from test_pages import wait_ready

pytestmark = pytest.mark.browser

BOX = "li[data-step='lagrange'] details.yourturn"
CODE = ("**", "_dot", "_ddot", "acos(", "sin(theta)")


def check_answer(p, box, answer):
    """Type an answer, press Check, wait until its result is in and typeset."""
    before = box.locator(".result").get_attribute("data-checked") or "0"
    box.locator("input").fill(answer)
    box.locator("button.check").click()
    p.wait_for_function(
        "([b, n]) => (b.dataset.checked || '0') !== n",
        arg=[box.locator(".result").element_handle(), before],
    )


def test_your_turn_feedback_is_math_replaced_and_announced(server, page):
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum")
    wait_ready(page)
    box = p.locator(BOX).nth(1)  # the equation of motion for theta
    box.locator("summary").click()
    result = box.locator(".result")
    assert result.get_attribute("aria-live") == "polite"
    assert box.locator(".result .feedback").count() == 1  # the feedback sits in the live region

    # a sign error: the term is named, as math
    check_answer(p, box, "theta'' - g/l sin(theta) = 0")
    assert "Not yet" in box.locator(".verdict").inner_text()
    items = box.locator(".feedback li")
    assert items.count() >= 1
    assert box.locator(".feedback mjx-container").count() >= 1
    shown = box.locator(".feedback").inner_text()
    assert "Sign error" in shown
    assert not any(code in shown for code in CODE), shown
    first = items.count()
    # its g/l is a fraction at display size, as tall as two lines of the sentence's text
    # (inline, a fraction in a sentence shrinks to ~8 px per line: unreadable on a projector)
    ratio = p.evaluate(
        """(box) => Math.max(...[...box.querySelectorAll('.feedback mjx-container')]
              .filter((m) => m.querySelector('[data-mml-node="mfrac"]'))
              .map((m) => m.querySelector('svg').getBoundingClientRect().height
                          / parseFloat(getComputedStyle(m.closest('li')).fontSize)))""",
        box.element_handle(),
    )
    assert ratio >= 1.8, ratio

    # another wrong answer replaces the list (never stacked under the first)
    check_answer(p, box, "m l^2 theta'' = m g l sin(theta) + m theta'")
    second = box.locator(".feedback li").count()
    assert second >= 1
    text = box.locator(".feedback").inner_text()
    assert "Sign error" in text and not any(code in text for code in CODE), text
    assert second < first + 2  # not the old list plus the new one

    # a right answer: one verdict, no leftover feedback from the wrong ones
    check_answer(p, box, "m l^2 theta'' + m g l sin(theta) = 0")
    assert "Correct" in box.locator(".verdict").inner_text()
    assert "Sign error" not in box.locator(".feedback").inner_text()
    assert box.locator(".feedback li").count() == 1

    # an unreadable answer replaces all of it and points at the character typed
    check_answer(p, box, "theta'' + g/l sin(theta) +")
    verdict = box.locator(".verdict").inner_text()
    assert "Correct" not in verdict and "at character 26" in verdict, verdict
    assert box.locator(".verdict mark").count() == 1
    assert box.locator(".feedback li").count() == 0
    assert box.locator(".echo").inner_text() == ""
    assert [e for e in page.errors if "422" not in e] == []


def test_a_closed_boxs_prompt_is_typeset_when_opened_and_never_shown_as_source(server, page):
    """The prompts inside closed Your-turn boxes wait for their box (issue 13: the double
    pendulum's nine are work nobody sees with the step); opened, the prompt is math."""
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    wait_ready(page)
    boxes = p.locator("details.yourturn")
    assert boxes.count() == 9
    closed = p.evaluate(
        """() => [...document.querySelectorAll('details.yourturn .prompt')].map((el) =>
             [el.querySelectorAll('mjx-container').length, el.style.visibility])"""
    )
    assert closed == [[0, "hidden"]] * 9  # untouched, and its LaTeX source out of sight
    # the summary is seen with the step, so it is math already
    assert boxes.nth(0).locator("summary mjx-container").count() == 1
    box = boxes.nth(5)  # the equation of motion for theta1
    box.locator("summary").click()
    prompt = box.locator(".prompt")
    p.wait_for_function(
        "(el) => el.querySelector('mjx-container') && el.style.visibility === ''",
        arg=prompt.element_handle(),
    )
    assert "\\(" not in prompt.inner_text()
    assert "equation of motion for" in prompt.inner_text()


def test_equilibria_closed_forms_are_math(server, page):
    p = page.page
    p.goto(f"{server}/scenes/bead_on_hoop?Omega=6")
    wait_ready(page)
    p.wait_for_function(
        "[...document.querySelectorAll('#equilibria li')].length === 4"
        " && document.querySelectorAll('#equilibria .closed mjx-container').length >= 2"
    )
    panel = p.inner_text("#equilibria")
    assert "acos(" not in panel and "**" not in panel and "Omega" not in panel, panel
    assert "arccos" in panel  # MathJax's assistive text of \arccos
    # the existence condition |g/(Ω² R)| ≤ 1 is typeset too
    assert "exists when" in panel and "≤" in panel
    assert page.errors == []


def test_equilibria_found_by_the_search_show_no_placeholder_condition(server, page):
    """The elastic pendulum's equilibria come from the numeric search (exists_when 'numeric'):
    the panel said '(exists when numeric)' (student play-test)."""
    p = page.page
    p.goto(f"{server}/scenes/elastic_pendulum")
    wait_ready(page)
    p.wait_for_function("document.querySelectorAll('#equilibria li').length >= 2")
    panel = p.inner_text("#equilibria")
    assert "numeric)" not in panel and "exists when" not in panel, panel
    assert "below were found" not in panel


def test_a_wrong_answer_shows_what_it_predicts(server, page):
    """The button appears after a wrong answer only; it draws both ghosts and both energies."""
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum")
    wait_ready(page)
    box = p.locator(BOX).nth(1)
    box.locator("summary").click()
    check_answer(p, box, "m l^2 theta'' + m g l sin(theta) = 0")
    assert box.locator(".predict-open").count() == 0  # nothing to predict for a right answer
    check_answer(p, box, "theta'' - g/l sin(theta) = 0")
    box.locator(".predict-open").click()
    box.locator("canvas.predict-ghosts[data-sample]").wait_for(timeout=60_000)
    summary = box.locator(".predict-summary")
    summary.locator("mjx-container").first.wait_for(timeout=30_000)
    assert "parts visibly" in summary.inner_text()
    assert box.locator("svg.predict-energy polyline").count() == 2
    assert "parted at t = 0.08 s" in box.locator(".predict-legend").inner_text()
    # a new check takes the prediction away with the old feedback
    check_answer(p, box, "m l^2 theta'' + m g l sin(theta) = 0")
    assert box.locator("canvas.predict-ghosts").count() == 0
    assert [e for e in page.errors if "422" not in e] == []
