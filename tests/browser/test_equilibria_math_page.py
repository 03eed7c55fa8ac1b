"""The equilibria panel's reasons are typeset math, not plain text with a caret.

An instructor saw 'a small displacement grows like e^(3.132 t)' and 'K = ∂²V/∂q²' as text in
the panel. Each reason now carries its math as $…$, which the panel hands to MathJax: every
reason holds mjx-container elements, the words left around them hold no notation, and the math
MathJax read is the closed form (the inverted pendulum grows like e^{√(g/l) t}).
"""

from __future__ import annotations

import math

import pytest

pytestmark = pytest.mark.browser

#: The words of a reason (its typeset math taken out) and the TeX MathJax read from it.
READ_REASONS = """() => [...document.querySelectorAll('#equilibria .why')].map((el) => {
  const words = el.cloneNode(true);
  words.querySelectorAll('mjx-container').forEach((m) => m.remove());
  const doc = window.MathJax.startup.document;
  return {words: words.textContent, math: doc.getMathItemsWithin(el).map((m) => m.math),
          typeset: el.querySelectorAll('mjx-container').length};
})"""


def reasons(page, server: str, scene: str) -> list[dict]:
    p = page.page
    p.goto(f"{server}/scenes/{scene}")
    p.wait_for_function(
        "document.querySelectorAll('#equilibria .why').length > 0 && [...document"
        ".querySelectorAll('#equilibria .why')].every((el) => el.querySelector('mjx-container'))",
        timeout=90_000,
    )
    return p.evaluate(READ_REASONS)


def test_the_reasons_are_typeset_with_no_caret_left_in_the_words(server, page):
    found = reasons(page, server, "simple_pendulum")
    assert len(found) == 2
    for r in found:
        assert r["typeset"] >= 2, r
        for mark in ("^", "e^(", "∂", "**", "_dot", "λ", "±", "\\", "$"):
            assert mark not in r["words"], (mark, r["words"])
    tex = [m for r in found for m in r["math"]]
    rate = f"{math.sqrt(9.81 / 1.0):.4g}"  # √(g/l), the scene's g = 9.81 and l = 1
    assert rf"e^{{{rate}\,t}}" in tex and rf"\lambda = \pm {rate}i" in tex
    # K is explained the first time, as math, by the Hessian of V (a potential stands behind it)
    assert r"\mathbf K = \partial^2 V/\partial q^2" in found[0]["math"]  # bold: a matrix
    assert "stiffness matrix" in found[0]["words"] and "stiffness" not in found[1]["words"]
    assert page.errors == []


def test_a_turning_frame_glosses_k_by_the_effective_potential(server, page):
    """The bead on the spinning hoop: K is the Hessian of the effective potential, not of V."""
    found = reasons(page, server, "bead_on_hoop")
    first = found[0]
    assert "Hessian of the effective potential" in first["words"]
    assert r"\mathbf K = \partial^2 V/\partial q^2" not in first["math"]
    assert all("^" not in r["words"] for r in found)
    assert page.errors == []
