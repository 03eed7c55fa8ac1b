"""The editor a student can write in (issue 26, item 4, front-end parts).

- The help lists every field of the spec, each with its meaning, its units where it has any, and
  a one-line example, built from the schema the API publishes (/openapi.json): the field list on
  the page is checked against the schema's own property names, model by model, and each example
  must be JSON that parses.
- On a phone (390×844) the editor is usable: the code box, the Derive button and the first
  problem are on the page's width, the problem is under the code, not over it.
"""

from __future__ import annotations

import json
import urllib.request

import pytest

pytestmark = pytest.mark.browser

MODELS = [
    "SceneSpec",
    "Body",
    "PointSpec",
    "Frame",
    "Inertia",
    "Gravity",
    "Spring",
    "Damper",
    "Force",
    "Potential",
    "Stop",
]


def schema(server: str) -> dict:
    with urllib.request.urlopen(f"{server}/openapi.json") as r:
        return json.load(r)["components"]["schemas"]


def test_the_help_lists_every_field_with_meaning_units_and_an_example(server, page, artifacts):
    p = page.page
    p.goto(f"{server}/editor?from=simple_pendulum")
    p.wait_for_function("document.getElementById('spec-help').dataset.ready === '1'")
    schemas = schema(server)
    for model in MODELS:
        shown = p.eval_on_selector_all(
            f"details.help-model[data-model='{model}'] dt > code",
            "cs => cs.map(c => c.textContent)",
        )
        assert shown == list(schemas[model]["properties"]), model
    rows = p.eval_on_selector_all(
        "details.help-model dd",
        "ds => ds.map(d => [d.textContent, d.querySelector('code.example')?.textContent])",
    )
    assert len(rows) >= 60
    for text, example in rows:
        assert example is not None and "(no description)" not in text, text
        json.loads(example)  # a one-line example that is the JSON one writes
    # units where a field has them: a mass in kg, a spring's stiffness in N/m, gravity in m/s²
    body = p.text_content("details.help-model[data-model='Body']")
    assert "kg" in body and "metres" in body
    spring = p.text_content("details.help-model[data-model='Spring']")
    assert "N/m" in spring
    p.screenshot(path=str(artifacts / "editor_help_1280.png"), full_page=False)


def test_the_editor_on_a_phone(server, page, sized, artifacts):
    p = page.page
    sized(390, 844)
    p.goto(f"{server}/editor?from=simple_pendulum")
    p.wait_for_function("document.querySelector('#spec').value.includes('bodies')")
    spec = p.input_value("#spec").replace('"mass": "m"', '"mass": "lenght"')
    p.fill("#spec", spec)
    p.click("#derive")
    p.locator("#code-note").wait_for(timeout=30_000)
    width = p.evaluate("document.documentElement.clientWidth")
    assert p.evaluate("document.documentElement.scrollWidth") <= width
    for sel in ["#code", "#derive", "#code-note"]:
        box = p.locator(sel).bounding_box()
        assert box["x"] >= 0 and box["x"] + box["width"] <= width + 1, sel
    code, note = p.locator("#code").bounding_box(), p.locator("#code-note").bounding_box()
    assert note["y"] >= code["y"] + code["height"] - 1
    assert code["height"] >= 300  # room to write in
    p.screenshot(path=str(artifacts / "editor_phone_390x844.png"))
