"""A share link opened in the browser: /s/{token} lands on the scene's page with the shared
sliders, method, time span, lecture mode and lecture step in place, values exact; a posted spec's
link opens the editor with that spec, derived and run in the shared state."""

from __future__ import annotations

import json
import urllib.request
from urllib.parse import urlparse

import pytest

pytestmark = pytest.mark.browser


def share(server: str, state: dict) -> dict:
    request = urllib.request.Request(
        f"{server}/api/v1/export/share",
        data=json.dumps(state).encode(),
        headers={"content-type": "application/json"},
    )
    with urllib.request.urlopen(request, timeout=30) as answer:
        return json.loads(answer.read())


def test_a_shared_link_restores_the_page_state(server, page):
    state = {
        "scene_id": "double_pendulum",
        "parameters": {"m2": 0.1 + 0.2, "l1": 1.25},
        "initial": {"theta1": 1 / 3, "theta2_dot": -0.75},
        "method": "rk4",
        "dt": 0.005,
        "t_end": 7,
        "lecture": True,
        "lecture_step": 2,
    }
    link = share(server, state)
    p = page.page
    p.goto(f"{server}{link['url']}")
    p.wait_for_selector("#n-m2", timeout=60_000)
    page.settle(60_000)
    assert urlparse(p.url).path == "/scenes/double_pendulum"
    # the number boxes hold the shared doubles exactly (JS reads repr's digits back) behind
    # what they show: four significant digits (0.30000000000000004 reads 0.3)

    def exact(sel: str) -> float:
        return float(p.get_attribute(sel, "data-exact") or p.input_value(sel))

    assert exact("#n-m2") == 0.1 + 0.2 and p.input_value("#n-m2") == "0.3"
    assert exact("#n-l1") == 1.25
    assert exact("#n-theta1") == 1 / 3 and p.input_value("#n-theta1") == "0.3333"
    assert exact("#n-theta2_dot") == -0.75
    assert p.input_value("#method") == "rk4"
    assert float(p.input_value("#t_end")) == 7
    assert p.evaluate("document.body.classList.contains('lecture')")
    # lecture_step 2 is the third step: three revealed, the third the current one
    p.wait_for_selector("#steps[data-typeset='1']", timeout=60_000)
    assert p.get_attribute("#steps", "data-revealed") == "3"
    assert page.errors == []


def test_a_shared_link_of_ones_own_spec_opens_it_in_the_editor(server, page):
    spec = {
        "title": "My swing",
        "coordinates": ["phi"],
        "parameters": {"m": 2.0, "L": 0.7, "g": 9.81},
        "initial": {"phi": 0.4},
        "bodies": [{"name": "seat", "mass": "m", "position": ["L*sin(phi)", "-L*cos(phi)", 0]}],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }
    link = share(server, {"scene": spec, "parameters": {"L": 0.9}, "initial": {"phi": 0.25}})
    p = page.page
    p.goto(f"{server}{link['url']}")
    p.wait_for_selector("#n-L", timeout=60_000)
    page.settle(60_000)
    assert urlparse(p.url).path == "/editor"
    assert json.loads(p.input_value("#spec")) == spec
    assert float(p.input_value("#n-L")) == 0.9
    assert float(p.input_value("#n-phi")) == 0.25
    assert p.text_content("#scene-title") == "My swing"
    assert page.errors == []
