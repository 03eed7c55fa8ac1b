"""Rigid bodies drawn as what they are (physics play-test 4, finding 3): a body whose centre keeps
its distance from O hangs on a rod from O only when O is a point of the body. A cylinder rolling
inside a cylinder is a disk of its own radius inside the surface it rolls on; a ladder sliding
down a frictionless wall is a rod from the wall to the floor (both drawn), pivoted nowhere.
Where things must be is worked out here from the specs' geometry, and checked on the canvas's
pixels."""

from __future__ import annotations

import json
import math

import pytest
from specs_beyond import cylinder_in_cylinder, ladder
from test_drawing import GREY_NEAR, pause, post_in_editor, project

pytestmark = pytest.mark.browser

#: Whether any pixel within `reach` px of each (x, y) (CSS pixels) is the first body's blue
#: (#1f6feb, opaque: the rod, the disk's rim), not the background or the grey surface.
BLUE_NEAR = """([points, reach]) => {
  const c = document.getElementById('canvas');
  const dpr = c.width / c.clientWidth;
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height);
  return points.map(([x, y]) => {
    for (let dy = -reach; dy <= reach; dy++) for (let dx = -reach; dx <= reach; dx++) {
      const px = Math.round((x + dx) * dpr), py = Math.round((y + dy) * dpr);
      if (px < 0 || py < 0 || px >= c.width || py >= c.height) continue;
      const k = 4 * (py * c.width + px);
      const [r, g, b, a] = [d.data[k], d.data[k + 1], d.data[k + 2], d.data[k + 3]];
      const blue = Math.abs(r - 31) < 40 && Math.abs(g - 111) < 40 && Math.abs(b - 235) < 30;
      if (a > 200 && blue) return true;
    }
    return false;
  });
}"""

CYLINDER = cylinder_in_cylinder()
R_OUT, R_IN = CYLINDER["parameters"]["R"], CYLINDER["parameters"]["r"]
THETA0 = CYLINDER["initial"]["theta"]

LADDER = ladder(stops=False)  # paused at its start: the run need not stop where the top leaves
L, PHI0 = LADDER["parameters"]["L"], LADDER["initial"]["theta"]

#: A rod pivoted at O like the catalog's physical pendulum, but placed by components in N: only
#: the run shows that O is a point of it (fixed in its frame R, seen from G).
PENDULUM_IN_N = {
    "title": "rod placed in N",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "initial": {"theta": 1.0, "theta_dot": 0.0},
    "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "theta"}],
    "bodies": [
        {
            "name": "rod",
            "kind": "rigid_body",
            "mass": "m",
            "frame": "R",
            "position": ["l/2*sin(theta)", "-l/2*cos(theta)", 0],
            "inertia": {"ixx": "m*l**2/12", "iyy": 0, "izz": "m*l**2/12"},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}


def at_start(p) -> dict:
    """Pause at the run's first frame (the spec's initial state); the camera there."""
    pause(p)
    p.eval_on_selector("#scrub", "s => { s.value = 0; s.dispatchEvent(new Event('input')); }")
    p.wait_for_timeout(300)
    assert p.get_attribute("#canvas", "data-frame") == "0"
    return json.loads(p.get_attribute("#canvas", "data-camera"))


def circle(center, radius, n, skip=lambda a: False):
    return [
        (center[0] + radius * math.cos(a), center[1] + radius * math.sin(a), 0.0)
        for a in (2 * math.pi * k / n for k in range(n))
        if not skip(a)
    ]


def test_a_cylinder_rolling_inside_a_cylinder_is_a_disk_inside_its_surface(server, page, artifacts):
    p = page.page
    post_in_editor(p, server, CYLINDER)
    cam = at_start(p)
    p.screenshot(path=str(artifacts / "rigid-cylinder.png"))
    pieces = p.get_attribute("#canvas", "data-pieces").split()
    assert "rolling-surface" in pieces and "support" not in pieces, pieces
    g = ((R_OUT - R_IN) * math.sin(THETA0), -(R_OUT - R_IN) * math.cos(THETA0))
    # the disk's rim: radius r about G (its name may hide a few points)
    rim = p.evaluate(BLUE_NEAR, [[project(cam, q) for q in circle(g, R_IN, 16)], 2])
    assert sum(rim) >= 13, rim
    # nothing blue just outside the rim, nor where the old 1.5 m rod ran (O to 2G)
    beyond = circle(g, 1.5 * R_IN, 16)
    rod = [(f * g[0], f * g[1], 0.0) for f in (0.0, 0.2, 0.4, 1.6, 1.9)]
    misses = p.evaluate(BLUE_NEAR, [[project(cam, q) for q in beyond + rod], 1])
    assert sum(misses) == 0, misses
    # the surface: the circle of radius R about O, grey; not drawn half-way in
    down = math.atan2(g[1], g[0])
    far = lambda a: abs(math.remainder(a - down, 2 * math.pi)) < 1.2  # noqa: E731 - near the disk
    on = p.evaluate(GREY_NEAR, [[project(cam, q) for q in circle((0, 0), R_OUT, 24)]])
    inside = p.evaluate(GREY_NEAR, [[project(cam, q) for q in circle((0, 0), 0.7, 12, far)]])
    assert sum(on) >= 21 and sum(inside) == 0, (on, inside)
    assert page.errors == []


def test_a_ladder_is_a_rod_from_the_wall_to_the_floor_pivoted_nowhere(server, page, artifacts):
    p = page.page
    post_in_editor(p, server, LADDER)
    cam = at_start(p)
    p.screenshot(path=str(artifacts / "rigid-ladder.png"))
    pieces = p.get_attribute("#canvas", "data-pieces").split()
    assert "rigid-rod" in pieces and "support" not in pieces, pieces
    # its ends: the top on the wall x = 0, the foot on the floor y = 0; the rod along R.y
    top, foot = (0.0, L * math.cos(PHI0), 0.0), (L * math.sin(PHI0), 0.0, 0.0)
    ends = p.evaluate(BLUE_NEAR, [[project(cam, top), project(cam, foot)], 2])
    assert ends == [True, True]
    # not beyond either end (the round cap reaches 4.5 px), nor at O, nor where the old drawing
    # (a rod from O through G) ran
    (tx, ty), (fx, fy) = project(cam, top), project(cam, foot)
    n = math.hypot(fx - tx, fy - ty)
    u = ((fx - tx) / n, (fy - ty) / n)
    past = [(tx - 9 * u[0], ty - 9 * u[1]), (fx + 9 * u[0], fy + 9 * u[1])]
    g = (L / 2 * math.sin(PHI0), L / 2 * math.cos(PHI0))
    old = [project(cam, (f * g[0], f * g[1], 0.0)) for f in (0.0, 0.3, 1.7)]
    assert p.evaluate(BLUE_NEAR, [past + old, 1]) == [False] * 5
    # the wall (x = 0) and the floor (y = 0) its ends slide on, grey; not off to the side
    assert "slide-line" in pieces, pieces
    lines = [(0.0, 1.2, 0.0), (0.0, 2.2, 0.0), (0.3, 0.0, 0.0), (1.1, 0.0, 0.0)]
    off = [(-0.3, 1.2, 0.0), (0.3, 1.2, 0.0), (1.1, 0.3, 0.0), (1.1, -0.3, 0.0)]
    assert p.evaluate(GREY_NEAR, [[project(cam, q) for q in lines]]) == [True] * 4
    assert p.evaluate(GREY_NEAR, [[project(cam, q) for q in off]]) == [False] * 4
    # its equilibrium sketch (upright at the wall) draws the rod and no support
    p.wait_for_function("document.querySelectorAll('#equilibria svg[data-ready]').length > 0")
    drawn = p.eval_on_selector_all(
        "#equilibria svg[data-ready]",
        "svgs => svgs.map(s => [s.querySelectorAll('[data-piece=support]').length,"
        " s.querySelectorAll('[data-piece=rigid-rod]').length])",
    )
    assert drawn and all(d == [0, 1] for d in drawn), drawn
    # the θ = π sketch is turned away (422: the ladder off the wall), which is not this test's
    page.errors[:] = [e for e in page.errors if "422" not in e]
    assert page.errors == []


def test_pinned_rods_still_hang_from_their_pivot(server, page):
    """The catalog's physical pendulum (placed in its own frame from O) and the same rod placed
    in N (pinned as the run shows) keep the rod from a pivot support at O."""
    p = page.page
    p.goto(f"{server}/scenes/physical_pendulum")
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    page.settle()
    pieces = p.get_attribute("#canvas", "data-pieces").split()
    assert "support" in pieces and "rigid-rod" not in pieces, pieces
    post_in_editor(p, server, PENDULUM_IN_N)
    cam = at_start(p)
    pieces = p.get_attribute("#canvas", "data-pieces").split()
    assert "support" in pieces and "rigid-rod" not in pieces, pieces
    # the rod from O through G to the far end at l (θ = 1)
    far = (math.sin(1.0), -math.cos(1.0), 0.0)
    assert p.evaluate(BLUE_NEAR, [[project(cam, (0.0, 0.0, 0.0)), project(cam, far)], 3]) == [
        True,
        True,
    ]
    page.settle()
    assert page.errors == []
