"""A body's name on a drawing never covers the pulley it hangs from (instructor play-test: the
catalog's Atwood machine wrote "mass1" across the pulley)."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.browser

#: <text> elements whose box overlaps a pulley (a circle larger than a pin) by more than a sliver.
TEXT_ON_PULLEY = """svg => {
  const pulleys = [...svg.querySelectorAll('circle')].filter(c => c.r.baseVal.value > 5)
    .map(c => c.getBBox());
  const out = [];
  for (const t of svg.querySelectorAll('text')) {
    const p = t.getBBox();
    for (const q of pulleys) {
      const w = Math.min(p.x + p.width, q.x + q.width) - Math.max(p.x, q.x);
      const h = Math.min(p.y + p.height, q.y + q.height) - Math.max(p.y, q.y);
      if (w > 1 && h > 1) out.push(t.textContent);
    }
  }
  return out;
}"""


def test_atwood_labels_clear_of_the_pulley(server, page):
    p = page.page
    p.goto(server)
    thumb = "svg[data-thumb='atwood_machine']"
    p.wait_for_selector(f"{thumb}[data-ready='1']", timeout=60_000)
    names = p.eval_on_selector(
        thumb, "svg => [...svg.querySelectorAll('text')].map(t => t.textContent)"
    )
    assert {"mass1", "mass2"} <= set(names)  # both bodies are named…
    assert p.eval_on_selector(thumb, "svg => svg.querySelectorAll('circle').length") >= 1
    assert p.eval_on_selector(thumb, TEXT_ON_PULLEY) == []  # …and neither across the pulley
    assert page.errors == []
