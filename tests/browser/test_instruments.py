"""The PhET-style instruments beside the animation (issue 13 item 7), checked on the simple
pendulum (m = l = 1, g = 9.81, released from rest at theta0 = 2 rad) against its closed forms:
the energy bars, single steps of one sample, the stopwatch on the simulation clock, the period
timer against the exact large-amplitude period, and a gravity preset that re-runs the scene."""

from __future__ import annotations

import math

import pytest
from scipy.special import ellipk

pytestmark = pytest.mark.browser

M, L, G, THETA0 = 1.0, 1.0, 9.81, 2.0
FPS = 30  # the page asks the server for 30 samples per second
DRAWN = 2  # and draws two frames per sample (one interpolated between two samples)


def exact_period(g: float) -> float:
    """The pendulum's period at amplitude theta0: 4 sqrt(l/g) K(sin^2(theta0/2))."""
    return 4 * math.sqrt(L / g) * float(ellipk(math.sin(THETA0 / 2) ** 2))


def at(p) -> tuple[int, float]:
    """The sample on screen and its time, as the instruments show it."""
    frame = int(p.get_attribute("#instruments", "data-frame"))
    return frame, float(p.get_attribute("#instruments", "data-t"))


def bars(p) -> dict[str, float]:
    return p.eval_on_selector_all(
        "#instruments rect[data-key]",
        "rs => Object.fromEntries(rs.map(r => [r.dataset.key, Number(r.dataset.value)]))",
    )


def seek(p, permille: int) -> None:
    p.eval_on_selector(
        "#scrub", "(s, v) => { s.value = v; s.dispatchEvent(new Event('input')); }", permille
    )
    p.wait_for_timeout(150)


def test_energy_bars_follow_the_motion_and_e_stays_put(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum?t_end=10")
    seek(p, 0)
    first = bars(p)
    assert set(first) == {"T", "V", "E"}  # no work from outside: no W bars
    assert first["T"] == pytest.approx(0, abs=1e-12)  # released from rest
    seen = [first]
    for permille in (37, 111, 250, 500, 777, 1000):
        seek(p, permille)
        seen.append(bars(p))
    # T moves with the pendulum; E = T + V does not (a conservative scene, DOP853 at 1e-9)
    assert max(b["T"] for b in seen) - min(b["T"] for b in seen) > 1.0
    for b in seen:
        assert b["E"] == pytest.approx(b["T"] + b["V"], abs=1e-9)
        assert b["E"] == pytest.approx(first["E"], abs=1e-6 * M * G * L)
    # one axis for every bar, up to the run's largest energy: T at the bottom, m g l (1 - cos θ0)
    hi = float(p.get_attribute("#instruments svg", "data-hi"))
    # (the samples straddle the bottom: within 1/60 s of it at 30 samples/s, T is 0.3 % short)
    assert hi == pytest.approx(M * G * L * (1 - math.cos(THETA0)), rel=5e-3)
    assert "arbitrary" in p.inner_text("#instruments")  # V's zero is said to be a choice
    assert page.errors == []


def test_single_steps_move_one_sample_with_buttons_and_keys(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum?t_end=10")
    seek(p, 300)
    f0, t0 = at(p)
    p.keyboard.press(".")
    p.wait_for_timeout(120)
    f1, t1 = at(p)
    # one measured sample (two drawn frames): where the free-body diagram is drawn too
    assert (f1, t1) == (f0 + DRAWN, pytest.approx(t0 + 1 / FPS, abs=1e-9))
    p.click("button[data-step='1']")
    p.wait_for_timeout(120)
    assert at(p)[0] == f0 + 2 * DRAWN
    p.keyboard.press(",")
    p.keyboard.press(",")
    p.keyboard.press(",")
    p.wait_for_timeout(120)
    f, t = at(p)
    assert (f, t) == (f0 - DRAWN, pytest.approx(t0 - 1 / FPS, abs=1e-9))
    assert p.get_attribute("#play", "aria-pressed") == "false"  # stepping keeps it paused
    assert p.inner_text("#clock") == f"t = {t:.2f} s"  # the page's clock agrees
    assert page.errors == []


def test_the_stopwatch_reads_the_simulation_clock(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum?t_end=10")
    seek(p, 0)
    p.select_option("#speed", "0.5")  # half speed: simulated seconds pass at half the wall's rate
    p.click("#play")
    p.click(".clocks button:has-text('Start')")
    p.wait_for_timeout(2000)
    p.click(".clocks button:has-text('Stop')")
    watch = p.eval_on_selector("#stopwatch", "o => ({...o.dataset})")
    elapsed = float(watch["elapsed"])
    # the samples' times where it was started and stopped, not the wall clock
    assert elapsed == pytest.approx(float(watch["to"]) - float(watch["from"]), abs=1e-9)
    assert 0.6 < elapsed < 1.6  # ~1 simulated second in 2 wall seconds
    p.wait_for_timeout(500)  # stopped: it holds while the animation plays on
    assert float(p.get_attribute("#stopwatch", "data-elapsed")) == elapsed
    p.click(".clocks button:has-text('Reset')")
    p.wait_for_timeout(100)
    assert float(p.get_attribute("#stopwatch", "data-elapsed")) == 0
    p.select_option("#speed", "1")
    assert page.errors == []


def test_period_timer_and_a_gravity_preset(server, page):
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum?t_end=20")
    seek(p, 1000)
    earth = float(p.get_attribute("#period", "data-period"))
    assert earth == pytest.approx(exact_period(9.81), rel=2e-3)
    run = p.get_attribute("#canvas", "data-run")
    p.click(".gravity-presets button[data-g='1.62']")  # the Moon
    assert p.input_value("#n-g") == "1.62"
    p.wait_for_function(
        f"document.querySelector('#canvas').dataset.run !== '{run}'", timeout=60_000
    )
    page.settle()
    # the slider moved with it (to within its own step)
    step = float(p.get_attribute("#s-g", "step"))
    assert float(p.input_value("#s-g")) == pytest.approx(1.62, abs=step)
    assert "g=1.62" in p.url  # and the link says so
    if p.get_attribute("#play", "aria-pressed") != "false":
        p.click("#play")
    seek(p, 1000)
    moon = float(p.get_attribute("#period", "data-period"))
    assert moon == pytest.approx(exact_period(1.62), rel=2e-3)
    assert p.get_attribute(".gravity-presets button[data-g='1.62']", "aria-pressed") == "true"
    assert page.errors == []
