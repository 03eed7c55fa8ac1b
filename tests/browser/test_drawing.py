"""What the animation draws, checked against geometry worked out here (issue 13 item 6): a posted
bead on a spinning parabola is drawn on its wire, turning with the frame; compare mode draws both
runs at one scale; equilibrium sketches put supports only at fixed points and give the bead its
hoop; a rolling disk is followed at one readable scale instead of shrinking to a dot."""

from __future__ import annotations

import json
import math

import pytest

pytestmark = pytest.mark.browser

A, OMEGA, G = 1.0, 3.0, 9.81
PARABOLA = {
    "title": "Bead on a spinning parabola",
    "coordinates": ["r"],
    "parameters": {"m": 0.2, "a": A, "Omega": OMEGA, "g": G},
    "units": {"r": "m"},
    "initial": {"r": 0.5, "r_dot": -0.3},
    "frames": [{"name": "H", "parent": "N", "axis": "y", "angle": "Omega*t"}],
    "bodies": [
        {"name": "bead", "mass": "m", "position": {"frame": "H", "components": ["r", "a*r**2", 0]}}
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}

#: Whether any pixel within 2 px of each (x, y) (CSS pixels) is the wire's grey (#868e96), not
#: the blue trail, the light floor grid or the empty background.
GREY_NEAR = """([points]) => {
  const c = document.getElementById('canvas');
  const dpr = c.width / c.clientWidth;
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height);
  return points.map(([x, y]) => {
    for (let dy = -2; dy <= 2; dy++) for (let dx = -2; dx <= 2; dx++) {
      const px = Math.round((x + dx) * dpr), py = Math.round((y + dy) * dpr);
      if (px < 0 || py < 0 || px >= c.width || py >= c.height) continue;
      const k = 4 * (py * c.width + px);
      const [r, g, b, a] = [d.data[k], d.data[k + 1], d.data[k + 2], d.data[k + 3]];
      const grey = Math.abs(r - 134) < 28 && Math.abs(g - 142) < 28 && Math.abs(b - 150) < 28;
      if (a > 120 && grey) return true;
    }
    return false;
  });
}"""


def project(cam: dict, p: tuple[float, float, float]) -> tuple[float, float]:
    """A world point on the canvas (CSS pixels), for the camera the stage reports: a turn by yaw
    about y, a tilt by pitch about x, a perspective divide; 2-D views drop z."""
    x, y, z = (p[k] - cam["center"][k] for k in range(3))
    f = 1.0
    if cam["is3D"]:
        cy, sy, cp, sp = (
            math.cos(cam["yaw"]),
            math.sin(cam["yaw"]),
            math.cos(cam["pitch"]),
            math.sin(cam["pitch"]),
        )
        x, z1 = cy * x + sy * z, -sy * x + cy * z
        y, z2 = cp * y - sp * z1, sp * y + cp * z1
        f = cam["camera"] / (cam["camera"] - z2)
    return cam["w"] / 2 + x * cam["scale"] * f, cam["h"] / 2 - y * cam["scale"] * f


def post_in_editor(p, server: str, spec: dict) -> None:
    p.goto(f"{server}/editor")
    p.wait_for_function("document.querySelector('#spec').value.length > 10", timeout=30_000)
    p.fill("#spec", json.dumps(spec, indent=2))
    p.click("#derive")
    p.wait_for_function(
        "document.querySelector('#canvas') && document.querySelector('#canvas').dataset.lastQ",
        timeout=90_000,
    )


def pause(p) -> None:
    if p.get_attribute("#play", "aria-pressed") != "false":
        p.click("#play")
    p.wait_for_timeout(200)


def test_a_bead_on_a_spinning_parabola_rides_its_wire_and_the_wire_turns(server, page, artifacts):
    p = page.page
    post_in_editor(p, server, PARABOLA)
    p.wait_for_timeout(800)
    pieces = p.get_attribute("#canvas", "data-pieces").split()
    assert "wire" in pieces and "axis" in pieces and "spin" in pieces
    found = 0
    # at two instants: the wire is where the frame has turned it (the bead and its name sit on
    # it somewhere and hide a few of the points)
    for attempt in range(2):
        pause(p)
        t = float(p.get_attribute("#instruments", "data-t"))
        cam = json.loads(p.get_attribute("#canvas", "data-camera"))
        c, s = math.cos(OMEGA * t), math.sin(OMEGA * t)
        # the wire at time t: r along H.x, a r^2 along H.y, H turned by Omega t about N.y
        us = [sign * (0.25 + 0.08 * k) for sign in (-1, 1) for k in range(6)]
        on = [(u * c, A * u * u, -u * s) for u in us]
        below = [(u * c, -A * u * u - 0.1, -u * s) for u in (-0.6, -0.45, 0.45, 0.6)]
        hits = p.evaluate(GREY_NEAR, [[project(cam, q) for q in on]])
        misses = p.evaluate(GREY_NEAR, [[project(cam, q) for q in below]])
        assert sum(hits) >= 8, (t, hits)
        found += sum(hits)
        assert sum(misses) == 0, (t, misses)
        p.screenshot(path=str(artifacts / f"parabola-wire-{attempt}.png"))
        p.click("#play")
        p.wait_for_timeout(700)
    assert found >= 19  # of 24
    assert page.errors == []


def test_a_bead_in_a_bowl_is_drawn_on_its_surface(server, page):
    """Two coordinates and a curved surface: a mesh of it, not a wire and not a floor."""
    bowl = {
        "title": "Bead in a bowl",
        "coordinates": ["u", "w"],
        "parameters": {"m": 0.2, "k": 0.8, "g": G},
        "initial": {"u": 0.6, "w": 0.0, "u_dot": 0.0, "w_dot": 1.2},
        "bodies": [{"name": "bead", "mass": "m", "position": ["u", "k*(u**2 + w**2)", "w"]}],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }
    p = page.page
    post_in_editor(p, server, bowl)
    p.wait_for_timeout(500)
    assert p.get_attribute("#canvas", "data-pieces").split() == ["surface"]
    assert p.get_attribute("#canvas", "data-view") == "3d"
    assert page.errors == []


def test_compare_mode_draws_both_runs_at_one_scale(server, page):
    p = page.page
    # Euler at a coarse step lets the oscillation grow: run B reaches farther than run A
    base = f"{server}/scenes/spring_mass_damper?t_end=10"
    p.goto(base)
    p.wait_for_function("document.querySelector('#canvas').dataset.scale", timeout=90_000)
    page.settle()
    alone = float(p.get_attribute("#canvas", "data-scale"))
    p.goto(f"{base}&compare=1&method_b=euler&dt=0.05")
    p.wait_for_function(
        "document.querySelector('#canvas').dataset.lastQ"
        " && document.querySelector('#canvas-b').dataset.scale",
        timeout=90_000,
    )
    page.settle()
    a = float(p.get_attribute("#canvas", "data-scale"))
    b = float(p.get_attribute("#canvas-b", "data-scale"))
    assert a == b
    assert a < 0.95 * alone  # fitted to B's wider swing, not to A's alone
    assert page.errors == []


def sketches(page, url: str, want: int) -> list:
    """The equilibrium sketches of a scene page, each as [supports, hoops]. A sketch whose run was
    turned away (a cold server busy deriving answers 503) is removed by the page: load it again,
    warm, until all `want` are drawn."""
    p = page.page
    for _ in range(3):
        p.goto(url)
        p.wait_for_function(
            "document.querySelectorAll('#equilibria li').length > 0", timeout=90_000
        )
        page.settle()
        drawn = p.eval_on_selector_all(
            "#equilibria svg[data-ready]",
            "svgs => svgs.map(s => [s.querySelectorAll('[data-piece=support]').length,"
            " s.querySelectorAll('[data-piece=hoop]').length])",
        )
        if len(drawn) >= want:
            return drawn
    return drawn


def test_equilibrium_sketches_hold_only_fixed_points_and_draw_the_hoop(server, page):
    # four equilibria of the double pendulum (each rod up or down); only the pivot O is fixed:
    # one support in each sketch, none at bob1
    assert sketches(page, f"{server}/scenes/double_pendulum", 4) == [[1, 0]] * 4
    # the bead on the spinning hoop: the hoop in every sketch (four equilibria at these
    # parameters: bottom, top and the two off-axis ones), and nothing drawn as a support
    assert sketches(page, f"{server}/scenes/bead_on_hoop", 4) == [[0, 1]] * 4
    page.errors[:] = [e for e in page.errors if "503" not in e]
    assert page.errors == []


def test_a_rolling_disk_is_followed_at_one_readable_scale(server, page):
    p = page.page
    p.goto(f"{server}/scenes/rolling_disk?t_end=10")
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    page.settle()
    pause(p)
    R = 0.3  # the scene's disk radius (m)
    scales = []
    for at in (0, 500, 1000):  # start, middle, end of a run that rolls ~160 m down the slope
        p.eval_on_selector(
            "#scrub", "(s, v) => { s.value = v; s.dispatchEvent(new Event('input')); }", at
        )
        p.wait_for_timeout(250)
        cam = json.loads(p.get_attribute("#canvas", "data-camera"))
        scales.append(cam["scale"])
        # the disk is on the canvas: some pixels of its blue (#1f6feb) rim
        blue = p.evaluate(
            """() => { const c = document.getElementById('canvas');
            const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0;
            for (let k = 0; k < d.length; k += 4)
              if (d[k + 3] > 200 && Math.abs(d[k] - 31) < 30 && Math.abs(d[k + 1] - 111) < 30
                  && Math.abs(d[k + 2] - 235) < 30) n++;
            return n; }"""
        )
        assert blue > 100, (at, blue)
    assert max(scales) == min(scales)  # no zooming out while it travels
    assert R * scales[0] >= 25  # px: a disk, not a dot
    assert page.errors == []


#: Pairs of <text> in an SVG whose rendered boxes overlap by more than a sliver.
OVERLAPPING_TEXT = """svg => {
  const boxes = [...svg.querySelectorAll('text')].map(t => [t.textContent, t.getBBox()]);
  const out = [];
  for (let i = 0; i < boxes.length; i++) for (let j = i + 1; j < boxes.length; j++) {
    const [a, p] = boxes[i], [b, q] = boxes[j];
    const w = Math.min(p.x + p.width, q.x + q.width) - Math.max(p.x, q.x);
    const h = Math.min(p.y + p.height, q.y + q.height) - Math.max(p.y, q.y);
    if (w > 1 && h > 1) out.push([a, b]);
  }
  return out;
}"""


@pytest.mark.parametrize("scene_id", ["spring_mass_damper", "coupled_oscillators"])
def test_spring_and_damper_labels_do_not_overlap(server, page, scene_id):
    p = page.page
    p.goto(f"{server}/scenes/{scene_id}")
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    page.settle()
    pause(p)
    for permille in (0, 333, 666):  # the diagram at a few instants, each force named once
        p.eval_on_selector(
            "#scrub", "(s, v) => { s.value = v; s.dispatchEvent(new Event('input')); }", permille
        )
        p.wait_for_timeout(300)
        assert p.locator("#fbd-svg text").count() >= 4  # forces and the body's name
        assert p.eval_on_selector("#fbd-svg", OVERLAPPING_TEXT) == []
    p.goto(server)  # the catalog's drawing names springs and dampers only where they fit
    p.wait_for_selector(f"svg[data-thumb='{scene_id}'][data-ready='1']", timeout=60_000)
    assert p.eval_on_selector(f"svg[data-thumb='{scene_id}']", OVERLAPPING_TEXT) == []
    assert page.errors == []
