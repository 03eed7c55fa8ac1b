"""The Your-turn box as an instructor's play-test found it: an empty box was sent as "0" and told
"✔ Correct" wherever the answer is 0 (the Atwood machine's Q_x), and the Q boxes asked for
"Q_x" while only the non-conservative part Q_x^NC is checked (students following the notes'
eq. 31 added the weight and were told "Extra term")."""

from __future__ import annotations

import json
import urllib.request

import pytest
from test_feedback import check_answer
from test_pages import wait_ready

pytestmark = pytest.mark.browser

Q_BOX = "li[data-step='forces'] details.yourturn"

#: The TeX sources typeset inside an element (what the room reads, as LaTeX): by MathJax on the
#: page, or ahead of time (static/js/prerendered.js keeps each one's TeX in data-tex), in order.
TEX_IN = """(el) => {
  const doc = window.MathJax?.startup?.document;
  const live = new Map((doc?.getMathItemsWithin ? doc.getMathItemsWithin(el) : [])
    .map((m) => [m.typesetRoot, m.math]));
  return [...el.querySelectorAll('mjx-container')]
    .map((c) => (c.dataset.prerendered !== undefined ? c.dataset.tex : live.get(c)))
    .filter((tex) => tex !== undefined);
}"""


def atwood_has_no_nonconservative_load(server: str) -> bool:
    """The scene's own spec: no damper, no applied force, no torque, so every Q_j^NC is 0."""
    with urllib.request.urlopen(f"{server}/api/v1/scenes/atwood_machine") as r:
        spec = json.load(r)["spec"]
    return not any(spec.get(k) for k in ("dampers", "forces", "torques", "friction"))


def test_an_empty_box_asks_for_an_answer_and_a_typed_zero_is_checked(server, page):
    assert atwood_has_no_nonconservative_load(server)  # so 0 is Q_x^NC: the trap of the bug
    p = page.page
    p.goto(f"{server}/scenes/atwood_machine")
    wait_ready(page)
    box = p.locator(Q_BOX).first
    box.locator("summary").click()
    checks: list[str] = []
    listen = lambda r: "/api/v1/check" in r.url and checks.append(r.post_data or "")  # noqa: E731
    p.on("request", listen)
    try:
        box.locator("button.check").click()
        p.wait_for_timeout(400)
        verdict = box.locator(".verdict").inner_text()
        assert "Type an answer first" in verdict
        assert "Correct" not in verdict
        assert checks == []  # nothing was sent
        box.locator("input").press("Enter")  # the same from the keyboard
        p.wait_for_timeout(300)
        assert checks == [] and "Type an answer first" in box.locator(".verdict").inner_text()

        # "Show answer" on an empty box: the derived answer, and no verdict on a 0 nobody typed
        before = box.locator(".result").get_attribute("data-checked") or "0"
        box.locator("button.reveal").click()
        p.wait_for_function(
            "([b, n]) => (b.dataset.checked || '0') !== n",
            arg=[box.locator(".result").element_handle(), before],
        )
        assert "✔" not in box.locator(".verdict").inner_text()
        assert "✘" not in box.locator(".verdict").inner_text()
        assert box.locator(".expected mjx-container").count() == 1

        # a 0 typed on purpose is an answer like any other, and right here
        check_answer(p, box, "0")
        assert "✔ Correct" in box.locator(".verdict").inner_text()
        assert json.loads(checks[-1])["answer"] == "0"
        # the weight is in V, not in Q_x^NC: adding it is no longer right
        check_answer(p, box, "(m1 - m2) g")
        assert "✔" not in box.locator(".verdict").inner_text()
    finally:
        p.remove_listener("request", listen)
    assert page.errors == []


def test_the_q_prompts_ask_for_the_nonconservative_part_as_the_forces_step_writes_it(server, page):
    p = page.page
    p.goto(f"{server}/scenes/atwood_machine")
    wait_ready(page)
    step = p.locator("li[data-step='forces']")
    # how the derivation's forces step writes it, read from its own line
    line = step.locator(".math-line .math").first.get_attribute("data-latex")
    written = line.split("=")[0].strip()
    assert "NC" in written, line
    box = step.locator("details.yourturn").first
    box.locator("summary").click()
    p.wait_for_function(
        "(b) => !b.querySelector('.prompt').style.visibility", arg=box.element_handle()
    )
    summary = p.evaluate(TEX_IN, box.locator("summary").element_handle())
    prompt = p.evaluate(TEX_IN, box.locator(".prompt").element_handle())
    assert summary == [written], summary
    assert prompt == [written], prompt
    # the provenance panel under that line ("Where each term of … comes from") says the same
    p.wait_for_selector("li[data-step='forces'] .pv-panel summary", state="attached")
    help_line = step.locator(".pv-panel summary").first
    assert p.evaluate(TEX_IN, help_line.element_handle()) == [written]
    assert page.errors == []
