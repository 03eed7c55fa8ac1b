"""What the new-student play-test found on the scene page, against independent values: the
energy bars on one readable scale (a rolling disk's closed form), a period timer that times only
what swings with a period (never a number for an Atwood machine or a disk rolling downhill), and
the other trust findings of the page (stale statistics, lecture mode's small print, "Your turn"
giving its answer away)."""

from __future__ import annotations

import math

import pytest
from lecture_keys import reveal_all

pytestmark = pytest.mark.browser

G = 9.81


def seek(p, permille: int) -> None:
    p.eval_on_selector(
        "#scrub", "(s, v) => { s.value = v; s.dispatchEvent(new Event('input')); }", permille
    )
    p.wait_for_timeout(150)


def bars(p) -> dict[str, float]:
    return p.eval_on_selector_all(
        "#instruments rect[data-key]",
        "rs => Object.fromEntries(rs.map(r => [r.dataset.key, Number(r.dataset.value)]))",
    )


def bar_sizes(p) -> dict[str, tuple[float, float]]:
    """Each bar's drawn (shorter, longer) side in CSS pixels, whichever way the bars lie: a bar
    of zero length is (0, its thickness)."""
    return p.eval_on_selector_all(
        "#instruments rect[data-key]",
        """rs => Object.fromEntries(rs.map(r => { const b = r.getBoundingClientRect();
             const w = b.width, h = b.height;
             return [r.dataset.key, [Math.min(w, h), Math.max(w, h)]]; }))""",
    )


def test_a_rolling_disks_energy_bars_share_one_readable_scale(server, page):
    """A uniform disk rolling from rest down an incline: ẍ = (2/3) g sin α, so at t_end the disk
    has gone x₁ = (1/3) g sin α t_end² and lost m g sin α x₁ of potential energy. Measured from
    the run's lowest V, V′(0) = E′ = m g sin α x₁ (~737 J), and E′ stays put while T and V′ trade
    it: every bar is drawn to a scale on which E is as long as the longest bar (E was 2.58 J beside
    T = 737 J and V = −735 J, too short to see)."""
    p = page.page
    m, R, alpha, t_end = 1.0, 0.3, 0.5, 10.0
    page.open_paused(f"{server}/scenes/rolling_disk?t_end={t_end:g}")
    x1 = G * math.sin(alpha) * t_end**2 / 3
    drop = m * G * math.sin(alpha) * x1
    seek(p, 0)
    start = bars(p)
    assert set(start) == {"T", "V", "E"}
    assert start["T"] == pytest.approx(0, abs=1e-9)
    assert start["V"] == pytest.approx(drop, rel=1e-6)
    assert start["E"] == pytest.approx(drop, rel=1e-6)
    assert float(p.get_attribute("#instruments svg", "data-lo")) == 0
    assert float(p.get_attribute("#instruments svg", "data-hi")) == pytest.approx(drop, rel=1e-6)
    sizes = bar_sizes(p)
    assert sizes["E"][1] > 100 and sizes["T"][0] < 1  # E reads as the whole axis, T as nothing yet
    for permille in (250, 500, 1000):
        seek(p, permille)
        b = bars(p)
        frac = permille / 1000
        assert b["T"] == pytest.approx(drop * frac**2, rel=1e-5)  # T ∝ x ∝ t²
        assert b["E"] == pytest.approx(drop, rel=1e-6)
        assert b["T"] + b["V"] == pytest.approx(b["E"], rel=1e-9)
    # the labels say the datum moved, and to where: V = m g y of the centre, y = R cos α − x sin α
    v_min = m * G * (R * math.cos(alpha)) - drop
    assert "V′" in p.inner_text("#instruments .energy-bars")
    assert f"min V = {v_min:.4g} J" in p.inner_text("#instruments .energy-bars")
    assert page.errors == []


@pytest.mark.parametrize("scene", ["atwood_machine", "rolling_disk"])
def test_no_period_where_nothing_swings(server, page, scene):
    """Both start from rest and accelerate uniformly (an Atwood machine's heavier side falls, a
    disk rolls down): the coordinate only grows, so no sample of the run may show a period."""
    p = page.page
    page.open_paused(f"{server}/scenes/{scene}")
    for permille in (0, 500, 1000):
        seek(p, permille)
        assert p.get_attribute("#period", "data-period") is None
        assert p.inner_text("#period") == "no period"
    assert "only rises" in p.inner_text("#instruments .clocks")
    assert page.errors == []


def test_swings_times_only_a_steady_swing(server, page):
    """`swings` on signals whose answer is known: cos(2πt/1.3) damped or not has period 1.3 s;
    a ramp and a parabola never swing back; sin(t²) swings faster and faster (no single period);
    a swing too slow for the run (period 40 s over 10 s) turns back but is not timed."""
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum")
    got = p.evaluate(
        """async () => {
          const { swings } = await import('/static/js/instruments.js');
          const t = [...Array(301).keys()].map((k) => k / 30);
          const of = (f) => { const r = swings(t, t.map(f));
            const n = r.ups.length;
            const period = n > 1 ? (r.ups[n - 1][1] - r.ups[0][1]) / (n - 1) : null;
            return [r.kind, period]; };
          return {
            cos: of((x) => Math.cos(2 * Math.PI * x / 1.3)),
            damped: of((x) => Math.exp(-0.3 * x) * Math.cos(2 * Math.PI * x / 1.3)),
            ramp: of((x) => 2 * x),
            fall: of((x) => -x * x),
            chirp: of((x) => Math.sin(x * x)),
            slow: of((x) => Math.cos(2 * Math.PI * x / 40 + 1)),
          };
        }"""
    )
    assert got["cos"][0] == "steady" and got["cos"][1] == pytest.approx(1.3, rel=1e-3)
    assert got["damped"][0] == "steady" and got["damped"][1] == pytest.approx(1.3, rel=2e-3)
    assert got["ramp"][0] == got["fall"][0] == "monotonic"
    assert got["chirp"][0] == "irregular"
    assert got["slow"][0] in ("few", "monotonic")
    assert page.errors == []


def test_a_refused_run_greys_the_last_runs_numbers_with_the_reason(server, page):
    """m = 0 leaves the pendulum no inertia (M = m l² = 0): the server refuses the run. The
    statistics, instruments, plots and work table still hold the last run's numbers; each is
    greyed and says why, until a run of values the server accepts comes in."""
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum")
    parts = ["#stats", "#instruments", ".plots .plot-grid", "#work-panel .work-grid"]
    stale = "sels => sels.map(s => document.querySelector(s).classList.contains('stale'))"
    assert p.evaluate(stale, parts) == [False] * 4
    p.fill("#n-m", "0")
    p.dispatch_event("#n-m", "change")
    p.wait_for_function("document.querySelector('#canvas').dataset.error", timeout=60_000)
    assert p.evaluate(stale, parts) == [True] * 4
    notes = p.eval_on_selector_all(".stale-note", "ns => ns.map(n => n.textContent)")
    assert len(notes) == 4
    for note in notes:
        assert "last run" in note and "refused" in note and "parameters.m" in note
    p.fill("#n-m", "1.5")
    p.dispatch_event("#n-m", "change")
    p.wait_for_function("!document.querySelector('#canvas').dataset.error", timeout=60_000)
    page.settle()
    assert p.evaluate(stale, parts) == [False] * 4
    assert p.locator(".stale-note").count() == 0
    # the refusal is the server's 422, which the page logs as a failed request: nothing else
    assert all("422" in e or "Unprocessable" in e for e in page.errors), page.errors


def visible_labels(p, step: str) -> list[str]:
    """The labels of the lines of a derivation step that are shown."""
    return p.eval_on_selector_all(
        f".step[data-step='{step}'] .math-line",
        """ls => ls.filter(l => l.getClientRects().length > 0)
             .map(l => l.dataset.label)""",
    )


def your_turn(p, step: str, k: int):
    return p.locator(f".step[data-step='{step}'] > .yourturn").nth(k)


def test_your_turn_hides_its_answer_until_it_is_earned(server, page):
    """A pendulum bob at l(sin θ, −cos θ): T = ½ m l² θ̇², V = −m g l cos θ (datum at the pivot),
    and θ̈ = −(g/l) sin θ. Opening "Your turn: T" hides T (and the bob's own T, the same
    expression); V stays. A correct V checked brings V's lines back; "Show answer" brings T's."""
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum")
    p.wait_for_selector(".step[data-step='energy'] .line-label")
    assert visible_labels(p, "energy") == ["T_bob", "V_bob", "T", "V"]
    your_turn(p, "energy", 0).locator("summary").click()
    assert visible_labels(p, "energy") == ["V_bob", "V"]
    assert p.locator(".step[data-step='energy'] .withheld-note").count() == 1
    box_v = your_turn(p, "energy", 1)
    box_v.locator("summary").click()
    assert visible_labels(p, "energy") == []
    box_v.locator("input").fill("-m g l cos(theta)")
    box_v.locator("button.check").click()
    p.wait_for_function(
        """() => document.querySelectorAll(".step[data-step='energy'] > .yourturn")[1]
                   .querySelector('.verdict.ok')"""
    )
    p.wait_for_timeout(100)
    assert visible_labels(p, "energy") == ["V_bob", "V"]  # earned; T still withheld
    your_turn(p, "energy", 0).locator("button.reveal").click()
    assert visible_labels(p, "energy") == ["T_bob", "V_bob", "T", "V"]
    assert p.locator(".step[data-step='energy'] .withheld-note").count() == 0
    # q̈ in the mass-matrix step: its line only; a wrong answer does not earn it
    box = your_turn(p, "matrix", 0)
    box.locator("summary").click()
    assert visible_labels(p, "matrix") == ["M", "f"]
    box.locator("input").fill("-g/l theta")
    box.locator("button.check").click()
    box.locator(".verdict.bad").wait_for()
    assert visible_labels(p, "matrix") == ["M", "f"]
    p.locator(".step[data-step='matrix'] .withheld-note button").click()
    assert visible_labels(p, "matrix") == ["M", "f", "theta_ddot"]


def test_the_answer_labels_of_each_kind_of_box(server, page):
    """answerLabels against a cart-pendulum's labels (x, θ): the second equation of motion is θ's
    with the three lines that work it out; Q and q̈ by the coordinate's place."""
    p = page.page
    page.open_paused(f"{server}/scenes/simple_pendulum")
    got = p.evaluate(
        """async () => {
          const { answerLabels } = await import('/static/js/page.js');
          const lag = ['L', 'dL/dx_dot', 'd/dt dL/dx_dot', 'dL/dx', 'EoM x',
                       'dL/dtheta_dot', 'd/dt dL/dtheta_dot', 'dL/dtheta', 'EoM theta'];
          return {
            T: answerLabels('energy', 0, ['T_cart', 'T_bob', 'V_cart', 'V_bob', 'T', 'V']),
            Qtheta: answerLabels('forces', 1, ['Q_x', 'Q_theta']),
            L: answerLabels('lagrange', 0, lag),
            eomTheta: answerLabels('lagrange', 2, lag),
            xdd: answerLabels('matrix', 0, ['M', 'f', 'x_ddot', 'theta_ddot']),
          };
        }"""
    )
    assert got["T"] == ["T_cart", "T_bob", "T"]
    assert got["Qtheta"] == ["Q_theta"]
    assert got["L"] == ["L"]
    assert got["eomTheta"] == ["EoM theta", "dL/dtheta_dot", "d/dt dL/dtheta_dot", "dL/dtheta"]
    assert got["xdd"] == ["x_ddot"]


# Every line of a provenance table's words (its header, caption and the origin of each term) that
# reaches past the derivation column's right edge, with its font size.
PAST_THE_COLUMN = """() => {
  const out = [];
  const column = document.querySelector("#steps").getBoundingClientRect();
  const words = ".pv-table caption, .pv-table th, .pv-table .pv-origin, .pv-table .pv-piece";
  for (const el of document.querySelectorAll(words)) {
    if (el.offsetParent === null || !el.textContent.trim()) continue;
    const range = document.createRange();
    range.selectNodeContents(el);
    const right = Math.max(...[...range.getClientRects()].map((r) => r.right));
    const size = parseFloat(getComputedStyle(el).fontSize);
    const text = el.textContent.trim().slice(0, 50);
    if (right > column.right + 1 || size < 24) out.push([text, right, size]);
  }
  return out;
}"""


@pytest.mark.parametrize("width, height", [(1024, 768), (1280, 720)])
def test_lecture_modes_provenance_words_wrap_in_the_column(server, page, sized, width, height):
    """Lecture mode at a projector's size: the provenance tables' words (the f table's header
    'right side minus the left side's terms free of q̈', each term's origin) wrap inside the
    derivation's column at lecture size (24 px), where they ran past its edge in a table wider
    than the column."""
    p = page.page
    sized(width, height)
    p.goto(f"{server}/scenes/double_pendulum?lecture=1")
    p.wait_for_function("() => document.getElementById('steps').dataset.typeset === '1'")
    reveal_all(p)
    p.wait_for_selector(".pv-panel")
    p.eval_on_selector_all(".pv-panel", "ds => ds.forEach((d) => { d.open = true; })")
    p.wait_for_function("() => document.querySelectorAll('.pv-table .pv-origin').length > 0")
    p.wait_for_timeout(300)
    header = p.locator(".pv-table th", has_text="right side minus").first
    assert header.is_visible()
    assert p.evaluate(PAST_THE_COLUMN) == []


def test_a_page_opened_on_refused_values_says_no_run_was_shown(server, page):
    """A link with m = 0 (hostile play-test: ?l=1e308…): there never was a run, so the greyed
    panels must not claim to hold 'the last run's numbers'."""
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum?m=0")
    p.wait_for_function("document.querySelector('#canvas').dataset.error", timeout=60_000)
    page.settle()
    notes = p.eval_on_selector_all(".stale-note", "ns => ns.map(n => n.textContent)")
    assert notes
    for note in notes:
        assert "no run has been shown yet" in note and "server refused" in note, note
        assert "last run" not in note
