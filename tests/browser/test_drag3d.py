"""Dragging bodies in a 3-D view (issue 13, item 2): a press on a body moves it, a press
elsewhere turns the camera. Where a dragged body lands is checked here from the scene's own
position formula (the spec's comment: the spherical pendulum's bob at
l (sin θ cos φ, −cos θ, −sin θ sin φ); the cone's particle at (r cos φ, r cot α, −r sin φ); the
hoop's bead at R (sin θ, −cos θ, 0) at t = 0) and the camera the canvas records
(canvas.dataset.camera: view.js's perspective, re-derived below), never from the page's solver.
"""

from __future__ import annotations

import json
import math

import pytest

pytestmark = pytest.mark.browser


# ---------------------------------------------------------------------------- the camera
def _axes(cam: dict) -> list[list[float]]:
    """The camera's right, up and toward-the-viewer axes in world coordinates: the world turned
    by yaw about y, then by pitch about the turned x (view.js)."""
    cy, sy = math.cos(cam["yaw"]), math.sin(cam["yaw"])
    cp, sp = math.cos(cam["pitch"]), math.sin(cam["pitch"])
    return [[cy, 0.0, sy], [sp * sy, cp, -sp * cy], [-cp * sy, sp, cp * cy]]


def _dot(a, b) -> float:
    return sum(x * y for x, y in zip(a, b, strict=True))


def _project(cam: dict, p) -> tuple[float, float, float]:
    """Screen x, y (CSS pixels of the canvas) and depth toward the viewer of world point p."""
    d = [p[k] - cam["center"][k] for k in range(3)]
    ex, ey, ez = _axes(cam)
    x, y, z = _dot(ex, d), _dot(ey, d), _dot(ez, d)
    f = cam["camera"] / (cam["camera"] - z)
    return cam["w"] / 2 + x * cam["scale"] * f, cam["h"] / 2 - y * cam["scale"] * f, z


def _unproject(cam: dict, sx: float, sy: float, depth: float) -> list[float]:
    """The world point drawn at (sx, sy) on the plane parallel to the screen at `depth`."""
    f = cam["camera"] / (cam["camera"] - depth)
    x = (sx - cam["w"] / 2) / (cam["scale"] * f)
    y = -(sy - cam["h"] / 2) / (cam["scale"] * f)
    ex, ey, ez = _axes(cam)
    return [cam["center"][k] + x * ex[k] + y * ey[k] + depth * ez[k] for k in range(3)]


# ---------------------------------------------------------------------------- the scenes
def _bob(theta: float, phi: float, length: float = 1.0) -> list[float]:
    s = math.sin(theta)
    return [length * s * math.cos(phi), -length * math.cos(theta), -length * s * math.sin(phi)]


def _cone(r: float, phi: float, alpha: float) -> list[float]:
    return [r * math.cos(phi), r / math.tan(alpha), -r * math.sin(phi)]


# ---------------------------------------------------------------------------- the page
def _ready(page, server: str, scene: str, query: str = "") -> None:
    p = page.page
    p.goto(f"{server}/scenes/{scene}{query}")
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    p.wait_for_function(
        "document.querySelector('#canvas').dataset.live === 'ready'", timeout=90_000
    )
    page.settle(90_000)
    p.wait_for_function("document.querySelector('#canvas').dataset.source === 'server'")


def _paused_at_start(p) -> None:
    p.evaluate(
        """() => { const s = document.getElementById('scrub'); s.value = '0';
                   s.dispatchEvent(new Event('input', { bubbles: true })); }"""
    )
    p.wait_for_function("document.querySelector('#play').getAttribute('aria-pressed') === 'false'")
    p.wait_for_function("document.querySelector('#canvas').dataset.frame === '0'")
    p.wait_for_timeout(100)


def _camera(p) -> dict:
    return json.loads(p.get_attribute("#canvas", "data-camera"))


def _screen(p) -> dict:
    return json.loads(p.get_attribute("#canvas", "data-screen"))


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

    def drag(self, a, b, steps: int = 6, up: bool = True) -> None:
        self.move(*a)
        self.p.mouse.down()
        for i in range(1, steps + 1):
            f = i / steps
            self.move(a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))
        if up:
            self.p.mouse.up()


def _value(p, name: str) -> float:
    return float(p.input_value(f"#n-{name}"))


def _query(p) -> dict:
    from urllib.parse import parse_qs, urlparse

    return {k: float(v[0]) for k, v in parse_qs(urlparse(p.url).query).items() if _num(v[0])}


def _num(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


# ---------------------------------------------------------------------------- the tests
def test_the_bob_dragged_lands_under_the_pointer_on_its_sphere(server, page):
    """θ, φ after the drag put l (sin θ cos φ, −cos θ, −sin θ sin φ) where the pointer was let
    go, and on the side of the sphere it was grabbed on (of the two points of the sphere drawn
    there, the one nearer the plane through the grabbed bob parallel to the screen)."""
    p = page.page
    _ready(page, server, "spherical_pendulum")
    _paused_at_start(p)
    cam = _camera(p)
    bob = _screen(p)["bob"]
    q0 = _query(p)
    theta0, phi0 = q0.get("theta", 1.0), q0.get("phi", 0.0)  # the scene's start: θ = 1, φ = 0
    depth0 = _project(cam, _bob(theta0, phi0))[2]
    assert _project(cam, _bob(theta0, phi0))[:2] == pytest.approx(bob, abs=0.05)
    target = (bob[0] + 45, bob[1] - 60)
    Pointer(p).drag(bob, target)
    q = _query(p)  # the URL carries the new start (the number boxes show it rounded)
    theta, phi = q["theta"], q["phi"]
    assert (_value(p, "theta"), _value(p, "phi")) == pytest.approx((theta, phi), abs=1e-3)
    x, y, depth = _project(cam, _bob(theta, phi))
    assert (x, y) == pytest.approx(target, abs=0.5)
    # the two points of the sphere on the pointer's ray: the bob is the one nearer depth0
    hits = _ray_sphere(cam, target, [0.0, 0.0, 0.0], 1.0)
    print("grabbed at depth", depth0, "sphere's points on the ray", hits, "bob", depth, (x, y))
    assert len(hits) == 2 and abs(hits[0] - hits[1]) > 0.2
    nearer, other = sorted(hits, key=lambda d: abs(d - depth0))
    assert abs(depth - nearer) < 0.02 < abs(depth - other)
    assert q["theta_dot"] == 0 and q["phi_dot"] == 0  # dropped from rest
    assert page.errors == []


def _ray_sphere(cam: dict, at_px, centre, radius: float) -> list[float]:
    """Depths of the points of a sphere drawn at screen point at_px (perspective: the ray from
    the eye, at depth cam.camera on the axis toward the viewer, through the pixel)."""
    ez = _axes(cam)[2]
    eye = [cam["center"][k] + cam["camera"] * ez[k] for k in range(3)]
    far = _unproject(cam, at_px[0], at_px[1], 0.0)  # the pixel's point on the depth-0 plane
    d = [far[k] - eye[k] for k in range(3)]
    o = [eye[k] - centre[k] for k in range(3)]
    a, b, c = _dot(d, d), 2 * _dot(o, d), _dot(o, o) - radius**2
    disc = b * b - 4 * a * c
    if disc < 0:
        return []
    out = []
    for s in ((-b - math.sqrt(disc)) / (2 * a), (-b + math.sqrt(disc)) / (2 * a)):
        point = [eye[k] + s * d[k] for k in range(3)]
        out.append(_dot(ez, [point[k] - cam["center"][k] for k in range(3)]))
    return out
