"""static/js/provenance.js on a real scene page: traceTerms() adds a "where each term comes from"
table under T, V, each Q_j and each equation of motion, typeset; hovering the polar Coriolis term
lights it and the term of T it was differentiated from. The provenance is computed here with the
engine and handed to the module, so the page part is tested before the derive response carries it.
"""

from __future__ import annotations

import pytest

from mechanics.derive import derivation_of_scene
from mechanics.provenance import provenance_json

pytestmark = pytest.mark.browser


def test_trace_terms_tables_and_hover(server, page, artifacts):
    p = page.page
    p.goto(f"{server}/scenes/central_force")
    p.wait_for_selector("#steps[data-typeset='1']", state="attached", timeout=90_000)
    prov = provenance_json(derivation_of_scene("central_force"))
    added = p.evaluate(
        """async (prov) => {
            const m = await import('/static/js/provenance.js');
            const panels = await m.traceTerms(document.getElementById('steps'), prov);
            panels.forEach((d) => { d.open = true; });
            return panels.length;
        }""",
        prov,
    )
    # T and V, Q_r and Q_θ, the EoM of r and of θ, M and f: one panel under each line.
    assert added == 8
    # M_22 θ̈ collects the θ equation's θ̈ term m r² θ̈: hovering the entry lights that term
    [inertia] = [
        t for t in prov["eom"]["theta"]["lhs"]["terms"] if t["plain"] == "m*r**2*theta_ddot"
    ]
    entry = p.locator("li[data-step=matrix] tbody.pv-term").filter(has_text="M")
    m22 = p.locator(f"li[data-step=matrix] tbody.pv-term[data-via='{inertia['id']}']")
    assert m22.count() == 1 and entry.count() >= 2
    m22.scroll_into_view_if_needed()
    m22.hover()
    term = p.locator(f"li[data-step=lagrange] tbody[data-term='{inertia['id']}']")
    assert "pv-from" in term.get_attribute("class")
    assert p.locator("li[data-step=energy] .pv-panel").count() == 2
    assert p.locator("li[data-step=lagrange] .pv-panel").count() == 2
    assert p.locator(".pv-panel mjx-container").count() > 10  # typeset, not LaTeX source
    # f's table subtracts terms as −\left(…\right): the TeX MathJax was given has no carriage
    # return and no bare 'left(' (a template literal once turned '\r' of '\right' into one)
    broken = p.evaluate(
        """() => [...Array.from(window.MathJax?.startup?.document?.math || []).map((m) => m.math),
                  ...[...document.querySelectorAll('mjx-container[data-prerendered]')]
                    .map((c) => c.dataset.tex)]
            .filter((tex) => /\\r|(?<!\\\\)left\\(/.test(tex))"""
    )
    assert broken == [], broken
    # The Coriolis term 2 m r ṙ θ̇ of the θ equation: from the ê_θ component, through d/dt ∂T/∂θ̇.
    [coriolis] = [
        t for t in prov["eom"]["theta"]["lhs"]["terms"] if t["plain"] == "2*m*r*r_dot*theta_dot"
    ]
    via = coriolis["sources"][0]["via"]
    row = p.locator(f"li[data-step=lagrange] tbody[data-term='{coriolis['id']}']")
    assert "component of v of planet" in row.inner_text()
    row.scroll_into_view_if_needed()
    row.hover()
    assert "pv-lit" in row.get_attribute("class")
    origin = p.locator(f"li[data-step=energy] tbody[data-term='{via}']")
    assert "pv-from" in origin.get_attribute("class")
    # ... and the lines it stands on, step by step: v of the planet, T, d/dt ∂L/∂θ̇, the EoM.
    lit = p.eval_on_selector_all(".math-line.pv-line", "rows => rows.map(r => r.dataset.label)")
    for label in ("v of planet", "T_planet", "T", "d/dt dL/dtheta_dot", "EoM theta"):
        assert label in lit, lit
    assert "V" not in lit and "EoM r" not in lit
    p.screenshot(path=str(artifacts / "provenance_central_force.png"))
    # A click keeps it lit after the pointer leaves; a second click lets go.
    row.click()
    p.mouse.move(2, 2)
    assert "pv-lit" in row.get_attribute("class")
    row.click()
    p.mouse.move(2, 2)
    assert "pv-lit" not in row.get_attribute("class")
    assert not page.errors
