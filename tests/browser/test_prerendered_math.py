"""The derivation's math is put up ready-made (static/js/prerendered.js) and is exactly what MathJax
renders now: a reader sees the same equations, with the same menu, as when MathJax typeset them.
"""

from __future__ import annotations

import json
import re

import pytest
from test_a11y import open_scene

from mechanics.scenes import scene_ids

pytestmark = pytest.mark.browser

#: In #steps: the equations on the page, how many are ready-made, and any TeX still unset (outside
#: the closed Your-turn prompts, which MathJax too leaves until they are opened).
COUNT = """() => {
  const steps = document.getElementById('steps');
  const walker = document.createTreeWalker(steps, NodeFilter.SHOW_TEXT);
  const raw = [];
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    if (n.parentElement.closest('.mathjax_ignore, mjx-container')) continue;
    if (/\\\\[\\[(]/.test(n.nodeValue)) raw.push(n.nodeValue.slice(0, 60));
  }
  return {all: steps.querySelectorAll('mjx-container').length,
          ready: steps.querySelectorAll('mjx-container[data-prerendered]').length, raw};
}"""

#: Each ready-made equation typeset again by MathJax, live, out of #steps at the font size of
#: its place; the formulas whose renderings differ.
COMPARE = """async () => {
  const ready = [...document.querySelectorAll('#steps mjx-container[data-prerendered]')];
  const box = document.createElement('div');
  box.style.cssText = 'position:absolute;left:-9999px;width:900px';
  for (const m of ready) {
    const p = document.createElement('p');
    p.style.fontSize = getComputedStyle(m.parentElement).fontSize; // as where it was put
    const tex = m.dataset.tex;
    p.textContent = m.dataset.display === 'true' ? `\\\\[${tex}\\\\]` : `\\\\(${tex}\\\\)`;
    box.append(p);
  }
  document.body.append(box);
  await MathJax.typesetPromise([box]);
  const plain = (el) => {
    const c = el.cloneNode(true);
    for (const a of ['ctxtmenu_counter', 'data-tex', 'data-display', 'data-prerendered']) {
      c.removeAttribute(a);
    }
    c.setAttribute('class', 'MathJax');
    return c.outerHTML;
  };
  const live = [...box.children].map((p) => p.querySelector('mjx-container'));
  const differ = ready.filter((m, i) => !live[i] || plain(m) !== plain(live[i]))
    .map((m) => m.dataset.tex);
  box.remove();
  return {compared: ready.length, differ};
}"""


def adopt_first(p) -> None:
    """Focus the first ready-made equation: it is typeset live in its place and keeps the focus,
    with MathJax's menu (speech, explorer) behind it — and MathJax is loaded for what follows."""
    p.evaluate("document.querySelector('#steps mjx-container[data-prerendered]').focus()")
    p.wait_for_function(
        "() => document.activeElement?.matches?.('#steps mjx-container:not([data-prerendered])')"
        " && /CtxtMenu_Attached/.test(document.activeElement.className)",
        timeout=30_000,
    )


@pytest.mark.parametrize("scene", sorted(scene_ids()))
def test_a_built_in_derivation_is_shown_ready_made_and_as_mathjax_renders_it(server, page, scene):
    p = page.page
    open_scene(page, server, scene)
    counted = p.evaluate(COUNT)
    assert counted["raw"] == [], counted["raw"][:3]
    assert counted["all"] > 10 and counted["ready"] == counted["all"], counted
    adopt_first(p)
    same = p.evaluate(COMPARE)
    assert same["compared"] == counted["all"] - 1
    assert same["differ"] == [], same["differ"][:3]
    assert page.errors == []


def test_the_spoken_mathml_is_out_of_sight_before_mathjax_has_run(server, page):
    p = page.page
    open_scene(page, server, "double_pendulum", "?lecture=1")
    hidden = p.evaluate(
        """() => [...document.querySelectorAll('#steps mjx-assistive-mml')].slice(0, 20)
             .map((m) => [getComputedStyle(m).position, m.getBoundingClientRect().width <= 2
                          || getComputedStyle(m).clip !== 'auto'])"""
    )
    assert hidden and all(pos == "absolute" and clipped for pos, clipped in hidden), hidden


def test_a_formula_the_file_lacks_is_typeset_live_and_the_rest_ready_made(server, fresh):
    """A file older than the derivation: what it lacks is typeset by MathJax, nothing is left as
    TeX, and what it has is still used."""
    p = fresh.new_page()
    dropped: list[str] = []

    def half(route):
        data = json.loads(route.fetch().text())
        keys = sorted(data["math"])
        for key in keys[::2]:
            dropped.append(key)
            del data["math"][key]
        route.fulfill(status=200, content_type="application/json", body=json.dumps(data))

    p.route(re.compile(r".*/math/simple_pendulum\.json$"), half)
    p.goto(f"{server}/scenes/simple_pendulum")
    p.wait_for_function("document.getElementById('steps').dataset.typeset === '1'", timeout=90_000)
    counted = p.evaluate(COUNT)
    assert dropped and counted["raw"] == []
    assert 0 < counted["ready"] < counted["all"]
    # the ones typeset live are MathJax's own items, with their menu
    orphans = p.evaluate(
        """() => {
          const roots = new Set([...MathJax.startup.document.math].map((m) => m.typesetRoot));
          return [...document.querySelectorAll('#steps mjx-container:not([data-prerendered])')]
            .filter((c) => !roots.has(c)).length;
        }"""
    )
    assert orphans == 0
