"""The scene in words for a screen reader (WCAG 2.2 AA; issue 26, item 6): an aria-live region
under the canvas lists the bodies, their positions, the coordinates and the energies, said when
the animation is paused and at each step (`.`), never every frame while it plays.

The positions it says are checked against the pendulum's own geometry (x = l sin θ,
y = −l cos θ at the coordinate it says), and its energies against T + V = E.
"""

from __future__ import annotations

import math
import re

import pytest

pytestmark = pytest.mark.browser

NUMBER = r"(-?\d+(?:\.\d+)?(?:e[-+]?\d+)?)"


def said(p) -> str:
    return p.text_content("#scene-description") or ""


def test_pause_and_step_say_where_the_bodies_are_and_the_energies(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum")
    region = p.locator("#scene-description")
    assert region.get_attribute("aria-live") == "polite"
    p.wait_for_function(
        "document.getElementById('scene-description').textContent.includes('Paused')"
    )
    text = said(p)
    m = re.search(rf"bob at x = {NUMBER} m, y = {NUMBER} m", text)
    assert m, text
    theta = float(re.search(rf"θ = {NUMBER}", text).group(1))
    x, y = float(m.group(1)), float(m.group(2))
    # l = 1 m: on the unit circle, at the angle it says (to the digits it says)
    assert math.hypot(x, y) == pytest.approx(1.0, abs=2e-3)
    assert math.atan2(x, -y) == pytest.approx(theta, abs=3e-3)
    energies = dict(re.findall(rf"\b([TVE]) = {NUMBER} J", text))
    assert set(energies) == {"T", "V", "E"}, text
    total = float(energies["T"]) + float(energies["V"])
    assert float(energies["E"]) == pytest.approx(total, rel=2e-2, abs=2e-3)
    # a step forward is said anew, at its own time
    t0 = re.search(rf"t = {NUMBER} s", text).group(1)
    p.keyboard.press(".")
    p.wait_for_function(
        f"!document.getElementById('scene-description').textContent.includes('t = {t0} s')"
    )
    assert "Paused" in said(p)


def test_nothing_is_said_while_it_plays(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/double_pendulum")
    p.click("#play")
    p.wait_for_timeout(300)
    p.evaluate(
        """window.__said = 0; new MutationObserver(() => window.__said++)
             .observe(document.getElementById('scene-description'),
                      { childList: true, characterData: true, subtree: true })"""
    )
    p.wait_for_timeout(1500)
    assert p.evaluate("window.__said") == 0
    p.click("#play")  # paused: said once
    p.wait_for_timeout(600)
    assert p.evaluate("window.__said") >= 1
    assert "bob1" in said(p) and "bob2" in said(p)
