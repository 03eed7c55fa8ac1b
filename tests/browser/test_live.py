"""The live preview (issue 13, item 2): a slider moves the motion while it moves with no server
run in between, the preview says it is one until the server's run replaces it, and a body dragged
on the canvas sets the initial state to what the pointer asks for, computed here from the pixels.
"""

from __future__ import annotations

import json
import math

import pytest

pytestmark = pytest.mark.browser

CANVAS_SUM = """() => {
  const c = document.getElementById('canvas');
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let s = 0;
  for (let i = 0; i < d.length; i += 7) s = (s * 31 + d[i]) % 1000000007;
  return s;
}"""


def _ready(page, timeout=90_000):
    p = page.page
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=timeout)
    p.wait_for_function(
        "document.querySelector('#canvas').dataset.live === 'ready'", timeout=timeout
    )
    page.settle(timeout)
    p.wait_for_function("document.querySelector('#canvas').dataset.source === 'server'")


def _simulate_requests(p) -> list[str]:
    seen: list[str] = []
    p.on("request", lambda r: "/api/v1/simulate" in r.url and seen.append(r.url))
    return seen


def test_a_slider_moves_the_motion_live_and_the_server_runs_when_it_is_let_go(server, page):
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    _ready(page)
    assert "server run (dop853_c" in p.inner_text("#live-badge")
    stats = p.inner_text("#stats")
    runs = _simulate_requests(p)

    slider = p.locator("#s-theta1")
    box = slider.bounding_box()
    y = box["y"] + box["height"] / 2
    x0 = box["x"] + box["width"] * float(
        slider.evaluate("s => (s.value - s.min) / (s.max - s.min)")
    )
    p.mouse.move(x0, y)
    p.mouse.down()
    seen_values, previews = [], []
    for k in range(1, 6):
        before = int(p.get_attribute("#canvas", "data-previews") or 0)
        p.mouse.move(x0 - 12 * k, y)
        # each move: a new preview is drawn at the next animation frame
        p.wait_for_function(
            "n => Number(document.querySelector('#canvas').dataset.previews) > n", arg=before
        )
        previews.append(int(p.get_attribute("#canvas", "data-previews")))
        seen_values.append(float(p.input_value("#n-theta1")))
        assert p.get_attribute("#canvas", "data-source") == "live"
        badge = p.locator("#live-badge")
        assert badge.get_attribute("data-kind") == "preview"
        assert "live preview (browser RK4)" in badge.inner_text()
    assert len(set(seen_values)) == 5 and previews == sorted(previews)
    assert runs == []  # no server run while the slider moves
    assert p.inner_text("#stats") == stats  # the panel still shows the server's measured run
    p.mouse.up()
    p.wait_for_function("document.querySelector('#canvas').dataset.source === 'server'")
    assert len(runs) >= 1
    assert "server run (dop853_c" in p.inner_text("#live-badge")
    assert page.errors == []


def test_a_slider_input_is_drawn_within_a_few_frames(server, page):
    """The preview is drawn by the next animation frame after an input event (the issue asks
    for 50 ms; on a loaded test machine the bound here is looser, the measured time printed)."""
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    _ready(page)
    took = p.evaluate(
        """async () => {
          const s = document.getElementById('s-theta2'), c = document.getElementById('canvas');
          const out = [];
          for (let k = 0; k < 5; k++) {
            const before = Number(c.dataset.previews || 0);
            const t0 = performance.now();
            s.value = String(Number(s.value) + 0.05);
            s.dispatchEvent(new Event('input', { bubbles: true }));
            const frame = () => new Promise(requestAnimationFrame);
            while (Number(c.dataset.previews || 0) === before) await frame();
            out.push(performance.now() - t0);
          }
          return out;
        }"""
    )
    print("slider input -> preview drawn (ms):", [round(t, 1) for t in took])
    assert sorted(took)[2] < 250


def _screen(p) -> dict:
    return json.loads(p.get_attribute("#canvas", "data-screen"))


def _paused_at_start(p) -> None:
    """Paused at t = 0 (the scrub at its start), where the drawn bodies are the initial state."""
    p.evaluate(
        """() => { const s = document.getElementById('scrub'); s.value = '0';
                   s.dispatchEvent(new Event('input', { bubbles: true })); }"""
    )
    p.wait_for_function("document.querySelector('#play').getAttribute('aria-pressed') === 'false'")
    p.wait_for_function("document.querySelector('#canvas').dataset.frame === '0'")
    p.wait_for_timeout(100)  # a frame drawn while paused: the points' screen positions


def test_dragging_the_bob_sets_theta_to_the_pointers_angle(server, page):
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum")
    _ready(page)
    _paused_at_start(p)
    runs = _simulate_requests(p)
    pts = _screen(p)
    canvas = p.locator("#canvas").bounding_box()
    css_w = p.evaluate("() => document.getElementById('canvas').clientWidth")
    k = canvas["width"] / css_w  # page pixels per view pixel (1 unless the canvas is scaled)
    (ox, oy), (bx, by) = pts["O"], pts["bob"]
    r = math.hypot(bx - ox, by - oy)
    # to an angle of 0.6 rad right of straight down, at 80 % of the rod's length
    tx, ty = round(ox + 0.8 * r * math.sin(0.6)), round(oy + 0.8 * r * math.cos(0.6))
    p.mouse.move(canvas["x"] + k * bx, canvas["y"] + k * by)
    p.mouse.down()
    for f in (0.3, 0.6, 1.0):
        p.mouse.move(canvas["x"] + k * (bx + f * (tx - bx)), canvas["y"] + k * (by + f * (ty - by)))
    assert runs == []  # nothing asked of the server while dragging
    p.mouse.up()
    # the screen's y grows downward, the world's upward: θ from straight down is atan2(dx, dy)
    expected = math.atan2(tx - ox, ty - oy)
    assert float(p.input_value("#n-theta")) == pytest.approx(expected, abs=0.01)
    assert float(p.input_value("#n-theta_dot")) == 0
    p.wait_for_function("document.querySelector('#canvas').dataset.source === 'server'")
    assert len(runs) >= 1  # the server's run of the new start, on release
    assert "theta=" in p.url
    assert page.errors == []


def test_a_shift_drag_from_the_bob_sets_its_velocity(server, page):
    """θ̇ that gives the bob the velocity the arrow draws (tip = where it is after 1 s):
    v = Δr / 1 s, and for a bob at l(sin θ, −cos θ), θ̇ = (∂r/∂θ · v) / |∂r/∂θ|²."""
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum?theta=0.4")
    _ready(page)
    _paused_at_start(p)
    pts = _screen(p)
    canvas = p.locator("#canvas").bounding_box()
    k = canvas["width"] / p.evaluate("() => document.getElementById('canvas').clientWidth")
    (ox, oy), (bx, by) = pts["O"], pts["bob"]
    length = float(p.input_value("#n-l"))
    scale = math.hypot(bx - ox, by - oy) / length  # view pixels per metre
    theta = float(p.input_value("#n-theta"))
    dx, dy = 40, 25  # pixels, right and down
    p.keyboard.down("Shift")
    p.mouse.move(canvas["x"] + k * bx, canvas["y"] + k * by)
    p.mouse.down()
    p.mouse.move(canvas["x"] + k * (bx + dx / 2), canvas["y"] + k * (by + dy / 2))
    p.mouse.move(canvas["x"] + k * (bx + dx), canvas["y"] + k * (by + dy))
    p.mouse.up()
    p.keyboard.up("Shift")
    v = (dx / scale, -dy / scale)
    j = (length * math.cos(theta), length * math.sin(theta))
    expected = (j[0] * v[0] + j[1] * v[1]) / (j[0] ** 2 + j[1] ** 2)
    assert float(p.input_value("#n-theta_dot")) == pytest.approx(expected, rel=0.02, abs=0.02)
    assert float(p.input_value("#n-theta")) == pytest.approx(theta, abs=1e-6)  # not moved
    assert page.errors == []


def test_a_drag_keeps_sixty_frames_a_second(server, page):
    """While a body is dragged the page draws every animation frame (no server call, no long
    task): a double pendulum's lower bob dragged in a circle for ~1 s."""
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    _ready(page)
    _paused_at_start(p)
    pts = _screen(p)
    canvas = p.locator("#canvas").bounding_box()
    k = canvas["width"] / p.evaluate("() => document.getElementById('canvas').clientWidth")
    bx, by = pts["bob2"]
    p.evaluate(
        """() => { window.__frames = []; const f = (t) => { window.__frames.push(t);
                   if (window.__frames.length < 400) requestAnimationFrame(f); };
                   requestAnimationFrame(f); }"""
    )
    p.mouse.move(canvas["x"] + k * bx, canvas["y"] + k * by)
    p.mouse.down()
    for i in range(60):
        a = 2 * math.pi * i / 60
        p.mouse.move(
            canvas["x"] + k * (bx + 30 * math.sin(a)),
            canvas["y"] + k * (by - 30 + 30 * math.cos(a)),
        )
        p.wait_for_timeout(16)
    p.mouse.up()
    gaps = p.evaluate(
        "() => window.__frames.slice(1).map((t, i) => t - window.__frames[i]).slice(5, 60)"
    )
    gaps.sort()
    print(
        "frame gaps while dragging (ms), median and 90th percentile:",
        gaps[len(gaps) // 2],
        gaps[int(0.9 * len(gaps))],
    )
    assert gaps[len(gaps) // 2] < 40  # 60 fps is 16.7 ms; a loaded CI machine gets slack
    assert page.errors == []


def test_the_editors_own_spec_gets_a_live_preview_too(server, page):
    """A spec of one's own: its equations are printed for it (POST /api/v1/scenes/live), so its
    sliders move the motion live as well."""
    p = page.page
    p.goto(f"{server}/editor?from=simple_pendulum")
    p.wait_for_function("document.querySelector('#spec') && document.querySelector('#spec').value")
    p.click("#derive")
    p.wait_for_function("document.querySelector('#canvas').dataset.live", timeout=90_000)
    assert p.get_attribute("#canvas", "data-live") == "ready"  # not "unavailable: why"
    # the server's run stays on the canvas until something moves
    assert p.get_attribute("#canvas", "data-source") == "server"
    page.settle()
    runs = _simulate_requests(p)
    before = int(p.get_attribute("#canvas", "data-previews") or 0)
    p.evaluate(
        """() => { const s = document.getElementById('s-theta');
                   s.value = String(Number(s.value) - 0.3);
                   s.dispatchEvent(new Event('input', { bubbles: true })); }"""
    )
    p.wait_for_function(
        "n => Number(document.querySelector('#canvas').dataset.previews) > n", arg=before
    )
    assert p.get_attribute("#canvas", "data-source") == "live"
    assert runs == []
    assert page.errors == []


def test_the_preview_ends_where_a_mass_reaches_the_pulley(server, page):
    """The Atwood machine from rest: x = ½ a t², a = (m1 − m2) g / (m1 + m2), and the spec's stop
    'mass2 reaches the pulley' at x = l + d, so t = sqrt(2 (l + d) / a). The preview watches the
    spec's stops as the server does and ends there."""
    p = page.page
    p.goto(f"{server}/scenes/atwood_machine")
    _ready(page)
    p.evaluate(
        """() => { const s = document.getElementById('s-m1'); s.value = '2.6';
                   s.dispatchEvent(new Event('input', { bubbles: true })); }"""
    )
    p.wait_for_function("document.querySelector('#canvas').dataset.previewStop")
    m1, m2, d, length, g = (float(p.input_value(f"#n-{k}")) for k in ("m1", "m2", "d", "l", "g"))
    a = (m1 - m2) * g / (m1 + m2)
    expected = math.sqrt(2 * (length + d) / a)
    assert float(p.get_attribute("#canvas", "data-preview-stop")) == pytest.approx(
        expected, abs=2e-3
    )
    assert "mass2 reaches the pulley" in p.inner_text("#live-badge")
    assert page.errors == []
