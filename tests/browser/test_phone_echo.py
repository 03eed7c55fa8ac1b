"""A Your-turn result on a 390×844 phone (student play-test, round 2): the double pendulum's T
typed in full was echoed "read as" in one typeset line that ran to x = 509, and the whole page
scrolled sideways. Every math block of a result must stay in its box, scrolling inside it with a
cue when it is wider, as the steps' equations do; math that fits carries no cue."""

from __future__ import annotations

import pytest
from test_feedback import check_answer
from test_pages import wait_ready

pytestmark = pytest.mark.browser

T_BOX = "li[data-step='energy'] details.yourturn"
LONG_T = (
    "1/2 m1 l1^2 theta1'^2 + 1/2 m2 (l1^2 theta1'^2 + l2^2 theta2'^2"
    " + 2 l1 l2 theta1' theta2' sin(theta1 - theta2))"
)

#: Each typeset math of the result: where it ends against its box, whether it scrolls inside its
#: own box, and the cue drawn under the line that holds it.
MATH_IN_RESULT = """(result) => [...result.querySelectorAll('mjx-container')].map((m) => {
  const holder = m.closest('.echo, li, .expected');
  const box = result.getBoundingClientRect();
  const cs = getComputedStyle(m);
  return { where: holder.className || holder.tagName, right: m.getBoundingClientRect().right,
    boxRight: box.right, scrollW: m.scrollWidth, clientW: m.clientWidth, overflowX: cs.overflowX,
    cue: getComputedStyle(holder, '::after').content };
})"""


def t_box_on_a_phone(server, page, sized):
    """The double pendulum at 390×844, its first Your-turn box for T opened."""
    sized(390, 844)
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    wait_ready(page)
    box = p.locator(T_BOX).first
    box.locator("summary").click()
    return p, box


def test_a_wide_answer_scrolls_in_its_box_on_a_phone_and_the_page_does_not(server, page, sized):
    p, box = t_box_on_a_phone(server, page, sized)
    check_answer(p, box, LONG_T)
    result = box.locator(".result")
    maths = result.evaluate(MATH_IN_RESULT)
    assert len(maths) >= 2  # the echo and the feedback's math at least
    for m in maths:
        assert m["right"] <= m["boxRight"] + 1, m  # in its box, not past the screen
    echo = [m for m in maths if m["where"] == "echo"]
    assert len(echo) == 1
    # the echo is wider than a phone (this T has two long terms): it scrolls, with the cue
    assert echo[0]["scrollW"] > echo[0]["clientW"] + 20, echo
    assert echo[0]["overflowX"] in ("auto", "scroll")
    assert "scroll" in echo[0]["cue"]
    # a math that fits is as it was: no scrollbar, no cue
    for m in maths:
        if m["scrollW"] <= m["clientW"] + 1 and m["overflowX"] == "visible":
            assert m["cue"] in ("none", "normal", ""), m
    assert p.evaluate("document.documentElement.scrollWidth") <= 390
    # Show answer: the derived T is as wide, in a display of its own, and scrolls the same way
    before = result.get_attribute("data-checked")
    box.locator("button.reveal").click()
    p.wait_for_function(
        "([b, n]) => b.dataset.checked !== n", arg=[result.element_handle(), before]
    )
    for m in result.evaluate(MATH_IN_RESULT):
        assert m["right"] <= m["boxRight"] + 1, m
        if m["where"] == "expected" and m["scrollW"] > m["clientW"] + 1:
            assert "scroll" in m["cue"]
    assert p.evaluate("document.documentElement.scrollWidth") <= 390
    assert page.errors == []


def test_a_short_answer_on_a_phone_has_no_scroll_cue(server, page, sized):
    p, box = t_box_on_a_phone(server, page, sized)
    check_answer(p, box, "1/2 m1 l1^2 theta1'^2")
    maths = box.locator(".result").evaluate(MATH_IN_RESULT)
    echo = [m for m in maths if m["where"] == "echo"]
    assert len(echo) == 1 and "scroll" not in echo[0]["cue"]
    assert echo[0]["overflowX"] == "visible"
    assert page.errors == []
