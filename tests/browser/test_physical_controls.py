"""Physical controls and honest summaries on the page (issue 26, item 5, front-end parts).

- A mass's or a length's slider starts above 0 (at 0 every run is refused and every panel greys):
  its least value is a small positive one, and a slider pushed to it (Home) still runs. A
  parameter that may be 0 (a damping) keeps 0 in reach.
- A blown-up run in the statistics (compare mode) reads "blew up at t = …", at the first sample
  where its energy drift reached half its largest kinetic energy, computed here from the API's
  own run, instead of an error of "1" (0.98 printed to two digits).
"""

from __future__ import annotations

import json
import re
import urllib.request

import pytest

pytestmark = pytest.mark.browser

MINIMA = """() => Object.fromEntries([...document.querySelectorAll('#params input[type=range]')]
  .map((s) => [s.id.slice(2), Number(s.min)]))"""


def wait_run(p) -> None:
    p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
    p.wait_for_function(
        "() => (document.documentElement.dataset.pending || '0') === '0'", timeout=60_000
    )


@pytest.mark.parametrize(
    "scene,positive,may_be_zero",
    [
        ("simple_pendulum", ["m", "l"], []),
        ("double_pendulum", ["m1", "m2", "l1", "l2"], []),
        ("spring_mass_damper", ["m", "L0"], ["c", "F0"]),
    ],
)
def test_mass_and_length_sliders_start_above_zero(server, page, scene, positive, may_be_zero):
    p = page.page
    p.goto(f"{server}/scenes/{scene}")
    wait_run(p)
    minima = p.evaluate(MINIMA)
    for name in positive:
        assert minima[name] > 0, (name, minima)
    for name in may_be_zero:
        assert minima[name] == 0, (name, minima)


def test_a_mass_slider_at_its_least_value_still_runs(server, page):
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum")
    wait_run(p)
    runs = p.get_attribute("#canvas", "data-run")
    p.focus("#s-m")
    p.keyboard.press("Home")  # the slider's least value, as a student drags it to the left
    p.wait_for_function(
        f"document.querySelector('#canvas').dataset.run !== {runs!r}", timeout=60_000
    )
    wait_run(p)
    assert float(p.input_value("#n-m")) > 0
    assert p.get_attribute("#canvas", "data-error") is None
    assert p.locator(".stale").count() == 0


def first_blow_up(server: str, body: dict) -> tuple[float, float]:
    """The API's own run: its energy error and the first sample time where |E − E₀| ≥ ½ max T."""
    req = urllib.request.Request(
        f"{server}/api/v1/simulate",
        data=json.dumps(body).encode(),
        headers={"content-type": "application/json"},
    )
    with urllib.request.urlopen(req) as r:
        run = json.load(r)
    E, T = run["energy"]["E"], run["energy"]["T"]
    scale = max(abs(x) for x in T)
    i = next(k for k, e in enumerate(E) if abs(e - E[0]) >= 0.5 * scale)
    return run["stats"]["energy_error"], run["t"][i]


def test_a_blown_up_run_reads_blew_up_at_its_time(server, page):
    p = page.page
    error, at = first_blow_up(
        server,
        {"scene_id": "simple_pendulum", "method": "euler", "dt": 0.1, "t_end": 30, "fps": 30},
    )
    assert 0.9 < error < 1.05  # what the table printed as "0.98" or "1"
    p.goto(
        f"{server}/scenes/simple_pendulum?method=euler&dt=0.1&t_end=30&compare=1&method_b=DOP853&tol=1e-9"
    )
    wait_run(p)
    p.wait_for_function("document.querySelectorAll('#stats thead th').length === 3")
    row = p.locator("#stats tbody tr", has_text="energy error")
    cells = row.locator("td").all_inner_texts()
    m = re.match(r"blew up at t = ([\d.]+) s", cells[0])
    assert m, cells
    assert float(m.group(1)) == pytest.approx(at, abs=0.02)
    assert float(cells[1]) < 1e-3  # the accurate run keeps its number
