"""The free-body diagram reads at every instant (issue 26, item 5): no arrow is hidden under a
body (a short friction or push arrow drawn from the body's centre lay under the block drawn over
its foot), and no two labels overlap, on every built-in scene, at three instants, on the page and
in lecture mode (whose labels are 24 px on the screen).

"Hidden" is measured on the diagram's own geometry (svg data-scale: each arrow's foot and tip;
data-bodies: the square each body covers): at least the arrow's head (10 px) lies outside every
opaque body. A wheel's face is drawn faint (its contact forces act on its rim and point across
it), so it does not hide an arrow.
"""

from __future__ import annotations

import json
import math
import urllib.request

import pytest
from test_drawing import OVERLAPPING_TEXT

pytestmark = pytest.mark.browser

HEAD_PX = 10


def outside(foot, tip, boxes) -> float:
    """Length (px) of the segment foot→tip outside every box, by sampling it finely."""
    n = 200
    length = math.dist(foot, tip)
    out = 0
    for k in range(n):
        t = (k + 0.5) / n
        x, y = foot[0] + t * (tip[0] - foot[0]), foot[1] + t * (tip[1] - foot[1])
        if not any(b[0] < x < b[2] and b[1] < y < b[3] for b in boxes):
            out += 1
    return length * out / n


def scene_ids(server: str) -> list[str]:
    with urllib.request.urlopen(f"{server}/api/v1/scenes") as r:
        return [s["id"] for s in json.load(r)]


def check_diagram(p, where: str) -> None:
    data = json.loads(p.get_attribute("#fbd-svg", "data-scale"))
    bodies = json.loads(p.get_attribute("#fbd-svg", "data-bodies"))
    opaque = [b["box"] for b in bodies if not b["wheel"]]
    for a in data["arrows"]:
        seen = outside(a["foot"], a["tip"], opaque)
        assert seen >= min(HEAD_PX, a["length"]) - 0.5, f"{where}: {a['label']} hidden: {a}"
    assert p.eval_on_selector("#fbd-svg", OVERLAPPING_TEXT) == [], where


@pytest.mark.timeout(900)
@pytest.mark.parametrize("lecture", [False, True])
def test_fbd_arrows_are_never_under_a_body_and_labels_never_overlap(server, page, sized, lecture):
    p = page.page
    if lecture:
        sized(1280, 720)
    for scene in scene_ids(server):
        page.open_paused(f"{server}/scenes/{scene}{'?lecture=1' if lecture else ''}")
        p.wait_for_function("document.getElementById('fbd-svg')?.dataset.scale", timeout=60_000)
        for permille in (0, 400, 800):
            p.eval_on_selector(
                "#scrub",
                "(s, v) => { s.value = v; s.dispatchEvent(new Event('input')); }",
                permille,
            )
            p.wait_for_timeout(250)
            check_diagram(p, f"{scene} at {permille / 10}% {'lecture' if lecture else ''}")
        page.settle()
