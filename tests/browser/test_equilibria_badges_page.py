"""The Equilibria panel as a student reads it (play-test findings 3, 5, 6).

- a marginal (neutral) equilibrium wears its own slate badge, not the unstable pink, and its
  text/background contrast is at least 4.5:1 (WCAG AA for its small type), computed here from
  the colours the browser resolved;
- the first K the panel shows is explained as the stiffness matrix, once;
- a free coordinate reads 'any φ' in the equilibrium's own line (it said 'φ = 0' there and
  'any φ' below it), and the spherical pendulum's bottom shows its two equal frequencies √(g/l)
  with one 'excite' button for the degenerate pair.
"""

from __future__ import annotations

import math
import re

import pytest

pytestmark = pytest.mark.browser


def open_equilibria(page, server: str, scene: str, query: str = "") -> None:
    p = page.page
    p.goto(f"{server}/scenes/{scene}{query}")
    p.wait_for_selector("#equilibria li .tag", state="attached", timeout=90_000)
    p.evaluate("document.querySelector('#equilibria').closest('details').open = true")
    page.settle()


def _luminance(rgb: str) -> float:
    channels = [int(c) / 255 for c in re.findall(r"\d+", rgb)[:3]]
    linear = [c / 12.92 if c <= 0.03928 else ((c + 0.055) / 1.055) ** 2.4 for c in channels]
    return 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]


def contrast(a: str, b: str) -> float:
    hi, lo = sorted((_luminance(a), _luminance(b)), reverse=True)
    return (hi + 0.05) / (lo + 0.05)


def badge_colours(p, index: int = 0) -> dict:
    return p.evaluate(
        """(i) => { const t = document.querySelectorAll('#equilibria .tag')[i];
        const s = getComputedStyle(t);
        return {text: t.textContent, cls: t.className, color: s.color, bg: s.backgroundColor}; }""",
        index,
    )


def test_a_neutral_family_has_its_own_badge_colour_and_k_is_explained(server, page):
    # m₁ = m₂: every x is an equilibrium, neutral (Q_x = (m₁ − m₂) g = 0)
    open_equilibria(page, server, "atwood_machine", "?m1=1.5&m2=1.5")
    p = page.page
    neutral = badge_colours(p)
    assert neutral["text"] == "marginal" and "neutral" in neutral["cls"]
    assert "unstable" not in neutral["cls"]
    assert contrast(neutral["color"], neutral["bg"]) >= 4.5
    items = p.locator("#equilibria li")
    assert items.count() == 1  # one family, not sampled points
    assert items.first.locator(".where").inner_text().replace("\n", "").startswith("any")
    why = p.locator("#equilibria .why").all_inner_texts()
    assert "stiffness matrix" in why[0]  # its K = ∂²V/∂q² typeset (test_equilibria_math_page)
    assert items.first.locator(".why mjx-container").count() >= 1
    # axe (as tests/browser/test_a11y.py runs it) on the panel with the neutral badge
    from axe_playwright_python.sync_playwright import Axe

    found = Axe().run(p, context="#equilibria").response["violations"]
    assert [v["id"] for v in found if v["impact"] in ("serious", "critical")] == []
    # and the unstable pink is another colour: the simple pendulum's top
    open_equilibria(page, server, "simple_pendulum")
    kinds = [badge_colours(p, i) for i in range(p.locator("#equilibria .tag").count())]
    unstable = next(k for k in kinds if k["text"] == "unstable")
    assert unstable["bg"] != neutral["bg"] and unstable["color"] != neutral["color"]
    why = " ".join(p.locator("#equilibria .why").all_inner_texts())
    assert why.count("stiffness matrix") == 1  # said the first time only
    assert page.errors == []


def test_the_spherical_pendulum_bottom_shows_two_equal_frequencies_and_any_phi(server, page):
    open_equilibria(page, server, "spherical_pendulum")
    p = page.page
    bottom = p.locator("#equilibria li").first
    where = bottom.locator(".where").inner_text()
    assert "any" in where and "=" in where
    freq = bottom.locator(".freq").inner_text().replace("\n", "")
    omega = f"{math.sqrt(9.81 / 1.0):.4g}"  # √(g/l) for the scene's g = 9.81, l = 1
    assert freq.count(omega) == 2, freq
    assert "degenerate" in bottom.locator(".why").inner_text()
    buttons = bottom.locator(".buttons button").all_inner_texts()
    assert buttons == ["start near", "excite mode 1"]
    assert page.errors == []
