"""A share link opened in the browser: /s/{token} lands on the scene's page with the shared
sliders, method, time span and lecture mode in place, values exact. (The lecture step travels as
``step`` in the page's query; restoring it is the page's part.)"""

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
    # the sliders' number boxes hold the shared doubles exactly (JS reads repr's digits back)
    assert float(p.input_value("#n-m2")) == 0.1 + 0.2
    assert float(p.input_value("#n-l1")) == 1.25
    assert float(p.input_value("#n-theta1")) == 1 / 3
    assert float(p.input_value("#n-theta2_dot")) == -0.75
    assert p.input_value("#method") == "rk4"
    assert float(p.input_value("#t_end")) == 7
    assert p.evaluate("document.body.classList.contains('lecture')")
    assert page.errors == []
