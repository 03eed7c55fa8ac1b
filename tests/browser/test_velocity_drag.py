"""A velocity drag sets the velocity at the instant the student grabbed (student play-test 3,
finding 1): paused at t = 5.8 s with the pendulum's bob at θ ≈ 1, a "drag sets: velocity" drag
from the bob made the bob jump to the scene's start (θ = 2) and drew the arrow there; on the
rolling disk, whose camera follows it, the disk left the view and x started at 0.

What the new start must be is read here from the server's own run (its JSON, the samples the
page drew), never from the page's drag code: the position at the paused sample, the rate from
the pointer's displacement through the spec's position formula (the arrow's tip is where the
body is after 1 s: v = Δr / 1 s, q̇ = J·v / |J|² for one coordinate). Where the arrow starts is
found in the canvas's pixels.
"""

from __future__ import annotations

import json
import math
from urllib.parse import parse_qs, urlparse

import pytest

pytestmark = pytest.mark.browser

ARROW_PIXELS = """() => {
  // canvas pixels of the velocity arrow's colour (#d9480f), in the view's CSS pixels
  const c = document.getElementById('canvas');
  const k = c.width / c.clientWidth;
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  const out = [];
  for (let y = 0; y < c.height; y++) for (let x = 0; x < c.width; x++) {
    const i = 4 * (y * c.width + x);
    const orange = Math.abs(d[i] - 217) < 12 && Math.abs(d[i + 1] - 72) < 12 && d[i + 2] < 40;
    if (orange) out.push([x / k, y / k]);
  }
  return out;
}"""


class Runs:
    """The server's runs the page receives while the test runs (their responses, newest last)."""

    def __init__(self, p) -> None:
        self.p = p
        self.seen: list = []
        p.on("response", self._keep)

    def _keep(self, response) -> None:
        # the canvas's run (run A asks for the constraint forces; other requests of the page,
        # such as an equilibrium's single sample, do not)
        request = response.request
        if "/api/v1/simulate" in response.url and request.method == "POST":
            if json.loads(request.post_data or "{}").get("constraint_forces"):
                self.seen.append(response)

    def last(self) -> dict:
        return self.seen[-1].json()

    def stop(self) -> None:
        self.p.remove_listener("response", self._keep)


def _ready(page, server: str, scene: str) -> None:
    p = page.page
    p.goto(f"{server}/scenes/{scene}")
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    p.wait_for_function(
        "document.querySelector('#canvas').dataset.live === 'ready'", timeout=90_000
    )
    page.settle(90_000)
    p.wait_for_function("document.querySelector('#canvas').dataset.source === 'server'")


def _pause_at(p, permille: int) -> float:
    """Scrubbed to `permille` of the run and paused there; the clock's time (a server sample)."""
    p.evaluate(
        """(v) => { const s = document.getElementById('scrub'); s.value = String(v);
                    s.dispatchEvent(new Event('input', { bubbles: true })); }""",
        permille,
    )
    p.wait_for_function("document.querySelector('#play').getAttribute('aria-pressed') === 'false'")
    p.wait_for_timeout(150)  # a frame drawn while paused: the points' screen positions
    return _clock(p)


def _clock(p) -> float:
    return float(p.inner_text("#clock").split()[2])


def _screen(p) -> dict:
    return json.loads(p.get_attribute("#canvas", "data-screen"))


def _camera(p) -> dict:
    return json.loads(p.get_attribute("#canvas", "data-camera"))


def _query(p) -> dict:
    out = {}
    for k, v in parse_qs(urlparse(p.url).query).items():
        try:
            out[k] = float(v[0])
        except ValueError:
            pass
    return out


def _at(run: dict, t: float, q: str) -> float:
    """The run's coordinate q at its sample nearest t (the paused clock sits on a sample)."""
    i = min(range(len(run["t"])), key=lambda j: abs(run["t"][j] - t))
    assert abs(run["t"][i] - t) < 0.006  # the clock shows 2 decimals
    return run["q"][q][i]


class Pointer:
    """The mouse in the canvas's CSS pixels (the view's units)."""

    def __init__(self, p) -> None:
        self.p = p
        self.box = p.locator("#canvas").bounding_box()
        self.k = self.box["width"] / p.evaluate(
            "() => document.getElementById('canvas').clientWidth"
        )

    def move(self, x: float, y: float) -> None:
        self.p.mouse.move(self.box["x"] + self.k * x, self.box["y"] + self.k * y)

    def press_and_move(self, a, b, steps: int = 6) -> None:
        self.move(*a)
        self.p.mouse.down()
        for i in range(1, steps + 1):
            f = i / steps
            self.move(a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))
            self.p.wait_for_timeout(20)
        self.p.wait_for_timeout(150)  # the preview of the new start drawn


def _velocity_mode(p, on: bool) -> None:
    want = "drag sets: velocity" if on else "drag sets: position, at rest"
    if p.inner_text("#drag-mode") != want:
        p.click("#drag-mode")
    assert p.inner_text("#drag-mode") == want


def _arrow_start(p, tip, press) -> tuple[float, float]:
    """Where the arrow drawn to `tip` starts on the canvas: its pixels on the line from the tip
    back toward where the body was pressed (within 3 px of it, the arrow's colour; the label
    lies past the tip), the one farthest from the tip."""
    ux, uy = press[0] - tip[0], press[1] - tip[1]
    n = math.hypot(ux, uy)
    ux, uy = ux / n, uy / n
    shaft = [
        (x, y)
        for x, y in p.evaluate(ARROW_PIXELS)
        if (x - tip[0]) * ux + (y - tip[1]) * uy > 0
        and abs((x - tip[0]) * uy - (y - tip[1]) * ux) < 3
    ]
    assert shaft, "no arrow drawn from the tip back toward where the body was taken"
    return max(shaft, key=lambda s: math.hypot(s[0] - tip[0], s[1] - tip[1]))


def test_a_velocity_drag_from_the_paused_bob_keeps_the_bob_where_it_is_drawn(server, page):
    p = page.page
    runs = Runs(p)
    try:
        _ready(page, server, "simple_pendulum")
        t_paused = _pause_at(p, 580)
        assert t_paused > 5  # far from the start, where θ = 2
        run = runs.last()
        theta = _at(run, t_paused, "theta")
        pts = _screen(p)
        (ox, oy), bob = pts["O"], pts["bob"]
        r_px = math.hypot(bob[0] - ox, bob[1] - oy)
        # the bob drawn is the run's sample: θ from straight down is atan2(dx, dy) on the screen
        assert math.atan2(bob[0] - ox, bob[1] - oy) == pytest.approx(theta, abs=1 / r_px)
        assert abs(theta - 2.0) > 0.3  # (the scene's start would be told apart)
        length = _query(p)["l"]
        scale = r_px / length  # view pixels per metre
        _velocity_mode(p, True)
        dx, dy = 35.0, 45.0  # pixels, right and down
        tip = (bob[0] + dx, bob[1] + dy)
        Pointer(p).press_and_move(bob, tip)
        # during the drag: the new start is the paused state, drawn where it was, clock at 0
        assert _clock(p) == 0
        assert p.get_attribute("#canvas", "data-frame") == "0"
        assert _screen(p)["bob"] == pytest.approx(bob, abs=1.0)
        start = _arrow_start(p, tip, bob)
        print("arrow starts at", start, "bob drawn at", bob)
        assert math.hypot(start[0] - bob[0], start[1] - bob[1]) < 2.5
        q = _query(p)
        assert q["theta"] == pytest.approx(theta, abs=1 / r_px)
        # θ̇ that gives the bob v = (dx, −dy) / scale: J = ∂r/∂θ = l (cos θ, sin θ)
        v = (dx / scale, -dy / scale)
        j = (length * math.cos(theta), length * math.sin(theta))
        expected = (j[0] * v[0] + j[1] * v[1]) / (j[0] ** 2 + j[1] ** 2)
        assert q["theta_dot"] == pytest.approx(expected, rel=0.02, abs=0.02)
        p.mouse.up()
        assert _clock(p) < 1.0  # it plays from the new start
        p.wait_for_function("document.querySelector('#canvas').dataset.source === 'server'")
        after = runs.last()
        assert after["q"]["theta"][0] == pytest.approx(q["theta"], abs=1e-9)
        assert after["q_dot"]["theta"][0] == pytest.approx(q["theta_dot"], abs=1e-9)
        _velocity_mode(p, False)
        assert page.errors == []
    finally:
        runs.stop()


def test_a_velocity_drag_keeps_a_followed_rolling_disk_in_view_where_it_was(server, page):
    """The camera follows the disk down the slope; paused at t = 5 s the disk is metres from
    x = 0. Its centre is at (x cos α + R sin α, −x sin α + R cos α): dragged 40 px to the right,
    v = (40 / scale, 0) and ẋ = v · ∂r/∂x = (40 / scale) cos α."""
    p = page.page
    runs = Runs(p)
    try:
        _ready(page, server, "rolling_disk")
        t_paused = _pause_at(p, 500)
        x_paused = _at(runs.last(), t_paused, "x")
        assert x_paused > 10  # metres down the slope: x = 0 is far out of this view
        cam = _camera(p)
        disk = _screen(p)["disk"]
        assert 0 < disk[0] < cam["w"] and 0 < disk[1] < cam["h"]
        alpha = _query(p)["alpha"]
        _velocity_mode(p, True)
        Pointer(p).press_and_move(disk, (disk[0] + 40, disk[1]))
        assert _clock(p) == 0
        during = _camera(p)
        assert during["center"] == pytest.approx(cam["center"], abs=1e-9)
        assert during["scale"] == pytest.approx(cam["scale"], rel=1e-9)
        assert _screen(p)["disk"] == pytest.approx(disk, abs=1.0)  # in view, where it was
        start = _arrow_start(p, (disk[0] + 40, disk[1]), disk)
        assert math.hypot(start[0] - disk[0], start[1] - disk[1]) < 2.5
        q = _query(p)
        assert q["x"] == pytest.approx(x_paused, abs=1 / cam["scale"])
        assert q["x_dot"] == pytest.approx(40 / cam["scale"] * math.cos(alpha), rel=0.02)
        p.mouse.up()
        p.wait_for_function("document.querySelector('#canvas').dataset.source === 'server'")
        assert runs.last()["q"]["x"][0] == pytest.approx(q["x"], abs=1e-9)
        _velocity_mode(p, False)
        assert page.errors == []
    finally:
        runs.stop()
