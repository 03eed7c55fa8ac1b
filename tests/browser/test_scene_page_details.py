"""What a new student's play-test of the scene pages found (issue 13, items 5–7), each checked
in a real page:

- the work–precision table says why every point left out of a fit was left out;
- the instruments (energy bars first) sit beside the animation on a wide window, under it on a
  narrow one, a phone and a projector in lecture mode, with nothing wider than the window;
- no plot legend covers an axis title, tick labels, the plot area or the plot's title;
- the initial-state number boxes show a few significant digits while the exact value is sent;
- the catalog shows placeholders and the server's warm-up progress until its drawings come;
- the editor's "Start from" list names the scene a shared spec came from (or "shared spec");
- a parse error reads as a plain sentence, with the marker where the problem is.

Expectations are worked out by hand from the inputs (the digits of π/4, where a '+' is in a
typed answer, how many cards the catalog has), not copied from what the page printed.
"""

from __future__ import annotations

import json
import math
import urllib.request
from decimal import Decimal
from urllib.parse import parse_qs, urlparse

import pytest
from test_pages import wait_ready

pytestmark = pytest.mark.browser

# Overlaps of a plotly figure's parts, per plot on the page: the legend against the axis titles,
# the x tick labels, the plot area and the figure's title; the x title against its tick labels;
# a legend or x title cut off by the figure's edge.
OVERLAPS = """() => {
  const box = (n) => {
    if (!n) return null;
    const r = n.getBoundingClientRect();
    return r.width && r.height ? r : null;
  };
  const hit = (a, b) => a && b && a.left < b.right - 1 && b.left < a.right - 1
    && a.top < b.bottom - 1 && b.top < a.bottom - 1;
  const out = {};
  for (const plot of document.querySelectorAll(".js-plotly-plot")) {
    if (!plot.offsetParent) continue;
    const legend = box(plot.querySelector(".legend .bg")) || box(plot.querySelector(".legend"));
    const parts = {
      xtitle: box(plot.querySelector(".g-xtitle text")),
      ytitle: box(plot.querySelector(".g-ytitle text")),
      area: box(plot.querySelector(".nsewdrag")),
      title: box(plot.querySelector(".g-gtitle text")),
    };
    const ticks = [...plot.querySelectorAll(".xtick text")].map(box).filter(Boolean);
    const bad = [];
    if (legend) {
      for (const k of Object.keys(parts)) if (hit(legend, parts[k])) bad.push(`legend covers ${k}`);
      if (ticks.some((t) => hit(legend, t))) bad.push("legend covers x tick labels");
    }
    if (ticks.some((t) => hit(parts.xtitle, t))) bad.push("x title on tick labels");
    const svg = box(plot.querySelector(".main-svg"));
    if (legend && legend.bottom > svg.bottom + 1) bad.push("legend cut off");
    if (parts.xtitle && parts.xtitle.bottom > svg.bottom + 1) bad.push("x title cut off");
    out[plot.id] = { bad, legend: Boolean(legend) };
  }
  return out;
}"""


def shown(x: float, digits: int) -> str:
    """x to `digits` significant digits as JavaScript's String(Number(x.toPrecision(d))) writes
    it: the shortest digits (Python's repr finds the same), in plain notation from 1e-6 to 1e21
    (0.00001, not 1e-05; 5, not 5.0), else as 3.16e-7."""
    text = repr(float(f"{x:.{digits}g}"))
    if "e" not in text:
        return text.removesuffix(".0")
    mantissa, exponent = text.split("e")
    if 1e-6 <= abs(float(text)) < 1e21:
        return format(Decimal(text), "f")
    return f"{mantissa}e{int(exponent):+d}"


def power(x: float) -> str:
    """x to 3 significant digits as JavaScript's toExponential() writes it: 1e-5, 3.16e-7."""
    d = Decimal(repr(float(f"{x:.3g}"))).normalize()
    sign, digits, _ = d.as_tuple()
    mantissa = Decimal((sign, digits, -(len(digits) - 1)))
    return f"{mantissa}e{d.adjusted():+d}"


def api(server: str, path: str, body: dict | None = None) -> dict:
    request = urllib.request.Request(
        f"{server}{path}",
        data=None if body is None else json.dumps(body).encode(),
        headers={"content-type": "application/json"},
    )
    with urllib.request.urlopen(request, timeout=60) as answer:
        return json.loads(answer.read())


def rect(p, selector: str) -> dict:
    return p.eval_on_selector(
        selector,
        "n => { const r = n.getBoundingClientRect(); "
        "return {left: r.left, right: r.right, top: r.top, bottom: r.bottom}; }",
    )


# ------------------------------------------------------------------------- 4. number boxes
def test_number_boxes_show_four_significant_digits(server, page):
    p = page.page
    p.goto(f"{server}/")
    shown = p.evaluate(
        """async () => {
          const { shownValue } = await import('/static/js/controls.js');
          return [Math.PI / 4, 2 * Math.PI / 3, -Math.PI / 18, 9.81, 1234.5, 0.1 + 0.2,
                  0.000123456, 0, 1].map((v) => shownValue(v));
        }"""
    )
    # π/4 = 0.785398…, 2π/3 = 2.094395…, −π/18 = −0.174532…: four significant digits each; an
    # integer part longer than four digits is kept whole; 0.1 + 0.2 is 0.3 to any sane eye
    assert shown == ["0.7854", "2.094", "-0.1745", "9.81", "1235", "0.3", "0.0001235", "0", "1"]


def test_a_restored_value_is_shown_rounded_and_sent_exactly(server, page):
    p = page.page
    exact = math.pi / 4  # 0.7853981633974483: what a share link or a drag leaves
    sent: list[dict] = []
    p.on(
        "request",
        lambda r: (
            r.method == "POST"
            and r.url.endswith("/api/v1/simulate")
            and sent.append(json.loads(r.post_data or "{}"))
        ),
    )
    p.goto(f"{server}/scenes/simple_pendulum?theta={exact!r}")
    wait_ready(page)
    assert p.input_value("#n-theta") == "0.7854"
    assert float(p.get_attribute("#n-theta", "data-exact")) == exact
    thetas = [b.get("initial", {}).get("theta") for b in sent]
    # the page's run starts at π/4 exactly; no run starts at the rounded 0.7854 (other runs,
    # the equilibria's, start elsewhere)
    assert exact in thetas and 0.7854 not in thetas, thetas
    # a slider moved: its value −π + 173·(2π/500) = −0.96761… is below the slider's resolution
    # past four digits, so it sets −0.9676, which the box, the link and the run all carry
    value = p.eval_on_selector(
        "#s-theta",
        "s => { s.value = String(Number(s.min) + 173 * Number(s.step));"
        " s.dispatchEvent(new Event('input', {bubbles: true}));"
        " s.dispatchEvent(new Event('change', {bubbles: true})); return Number(s.value); }",
    )
    assert abs(value - (-math.pi + 173 * 2 * math.pi / 500)) < 1e-12
    assert p.input_value("#n-theta") == "-0.9676"
    assert float(p.get_attribute("#n-theta", "data-exact")) == -0.9676
    page.settle()
    p.wait_for_function("() => location.search.includes('theta=-0.9676')")
    query = parse_qs(urlparse(p.url).query)
    assert float(query["theta"][0]) == -0.9676


def test_a_share_link_restores_exact_values_behind_rounded_boxes(server, page):
    state = {
        "scene_id": "double_pendulum",
        "parameters": {"m2": 0.1 + 0.2},
        "initial": {"theta1": 1 / 3},
    }
    link = api(server, "/api/v1/export/share", state)
    p = page.page
    p.goto(f"{server}{link['url']}")
    wait_ready(page)
    # 0.30000000000000004 reads 0.3 and 1/3 reads 0.3333; the page keeps (and links) every digit
    assert p.input_value("#n-m2") == "0.3"
    assert p.input_value("#n-theta1") == "0.3333"
    assert float(p.get_attribute("#n-m2", "data-exact")) == 0.1 + 0.2
    assert float(p.get_attribute("#n-theta1", "data-exact")) == 1 / 3
    query = parse_qs(urlparse(p.url).query)
    assert float(query["m2"][0]) == 0.1 + 0.2 and float(query["theta1"][0]) == 1 / 3


# ------------------------------------------------------------------------- 7. parse errors
def test_a_parse_error_is_a_plain_sentence_with_the_marker_after_the_operator(server, page):
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum")
    wait_ready(page)
    box = p.locator("li[data-step='lagrange'] details.yourturn").nth(1)
    box.locator("summary").click()
    typed = "theta'' + g/l sin(theta) +"
    before = box.locator(".result").get_attribute("data-checked") or "0"
    box.locator("input").fill(typed)
    box.locator("button.check").click()
    p.wait_for_function(
        "([b, n]) => (b.dataset.checked || '0') !== n",
        arg=[box.locator(".result").element_handle(), before],
    )
    verdict = box.locator(".verdict")
    text = verdict.inner_text()
    assert text.startswith("Can't read your answer"), text
    assert "syntax error" not in text and "answer: syntax" not in text, text
    # the whole answer as typed, the marker after its last '+' (the 26th character), where the
    # missing term would go; not before the '+'
    code = verdict.locator("code.typed")
    assert code.inner_text().replace("▸", "") == typed
    before_mark = code.evaluate("c => c.firstChild.textContent")
    assert before_mark == typed and before_mark.endswith("+")
    assert "'+'" in text and "character 26" in text, text


def test_parse_refusals_read_plainly(server, page):
    p = page.page
    p.goto(f"{server}/")
    cases = [  # (server's message, typed): the marker's place worked out by hand
        (
            "answer: syntax error: the expression ends with '+', a term is missing after it "
            "(at character 9: 1/2 m l ⟨here⟩+)",
            "1/2 m l +",
        ),
        (  # the same once the server points after the operator: the same place
            "answer: syntax error: the expression ends with '+', a term is missing after it "
            "(at character 10: 1/2 m l +⟨here⟩)",
            "1/2 m l +",
        ),
        (
            "answer: syntax error: a term is missing after '*' (at character 3: m ⟨here⟩* + l)",
            "m * + l",
        ),
        (  # mechanics/expr.py's newer wording, pointing after the operator
            "answer: a term is missing after '+' at the end (at character 10: 1/2 m l +⟨here⟩)",
            "1/2 m l +",
        ),
        (
            "answer: a term is missing after '^' (at character 4: m l^⟨here⟩ + 2)",
            "m l^ + 2",
        ),
        ("answer: ')' without a matching '(' (at character 6: theta⟨here⟩))", "theta))"),
        ("answer: empty expression", ""),
    ]
    got = p.evaluate(
        """async (cases) => {
          const { readRefusal } = await import('/static/js/derivation.js');
          return cases.map(([m, t]) => readRefusal(m, t));
        }""",
        cases,
    )
    assert [g["text"][: g["at"]] if g["at"] is not None else None for g in got] == [
        "1/2 m l +",
        "1/2 m l +",
        "m *",
        "1/2 m l +",
        "m l^",
        "theta",
        None,
    ]
    for g in got:
        assert g["sentence"].startswith("Can't read your answer: "), g
        assert "syntax error" not in g["sentence"], g
    assert "'+'" in got[0]["sentence"] and "character 9" in got[0]["sentence"]
    assert got[0]["sentence"] == got[1]["sentence"] == got[3]["sentence"]
    assert "'^'" in got[4]["sentence"] and "character 4" in got[4]["sentence"]


# ------------------------------------------------------------------------- 1. precision table
@pytest.mark.timeout(300)
def test_every_point_left_out_of_a_fit_says_why(server, page):
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    wait_ready(page)
    p.click("#precision-panel summary")
    p.wait_for_selector("#precision .methods[data-ready='1']", timeout=60_000)
    p.fill("#precision-t-end", "5")
    with p.expect_response("**/api/v1/precision", timeout=180_000) as answer:
        p.click("#precision-run")
    result = answer.value.json()
    p.wait_for_selector("#precision[data-state='done']", timeout=60_000)
    # the double pendulum from 120° is chaotic: Euler at h ≥ 2.5 ms has no digit right after 5 s
    euler = next(m for m in result["methods"] if m["method"] == "euler")
    assert any(pt["excluded"] for pt in euler["points"])
    for m in result["methods"]:
        left = [pt for pt in m["points"] if pt["excluded"]]
        rows = p.locator(f"#precision-orders tr.left-out[data-left-out-of='{m['method']}']")
        if not left:
            assert rows.count() == 0
            continue
        text = rows.inner_text()
        for pt in left:
            setting = shown(pt["setting"], 3) if m["kind"] == "fixed" else power(pt["setting"])
            assert setting in text and pt["excluded"] in text, (m["method"], setting, text)
        if m["points_in_fit"] < 2:
            assert "no fitted order" in text
    # its three log-log plots' legends are clear of their titles, tick labels and data
    p.eval_on_selector("#precision-plot-energy", "n => n.scrollIntoView()")
    p.wait_for_timeout(300)
    found = p.evaluate(OVERLAPS)
    for plot in ("time", "evals", "energy"):
        assert found[f"precision-plot-{plot}"] == {"bad": [], "legend": True}, found
    # the orders table still has one row per method (what test_precision_page reads)
    assert p.locator("#precision-orders tr[data-method]").count() == len(result["methods"])


# ------------------------------------------------------------------------- 2. instruments beside
def instruments_beside(p) -> bool:
    canvas, fold = rect(p, "#canvas"), rect(p, ".instruments-fold")
    return fold["left"] >= canvas["right"] and fold["top"] < canvas["bottom"]


def instruments_below(p) -> bool:
    return rect(p, ".instruments-fold")["top"] >= rect(p, "#canvas")["bottom"]


def assert_no_overflow(p, where: str) -> None:
    wide = p.evaluate("document.documentElement.scrollWidth - window.innerWidth")
    assert wide <= 0, f"{where}: the page is {wide} px wider than the window"


@pytest.mark.timeout(300)
def test_energy_bars_beside_the_animation_on_a_wide_window_only(server, page, sized):
    p = page.page
    for scene in ("double_pendulum", "spring_mass_damper"):
        sized(1400, 900)
        p.goto(f"{server}/scenes/{scene}")
        wait_ready(page)
        assert instruments_beside(p), scene
        bars, canvas = rect(p, "#instruments .energy-bars"), rect(p, "#canvas")
        assert bars["top"] < canvas["bottom"], "the energy bars start beside the canvas"
        # drawn in its own pixels: a bar's value label is at least 9 px tall on screen
        label = p.eval_on_selector(
            "#instruments text[data-value-of='T']", "t => t.getBoundingClientRect().height"
        )
        assert label >= 9
        assert_no_overflow(p, f"{scene} at 1400")
        for w, h, lecture in ((1024, 768, False), (390, 844, False), (1024, 768, True)):
            sized(w, h)
            if lecture:
                p.goto(f"{server}/scenes/{scene}?lecture=1")
                wait_ready(page)
            p.wait_for_timeout(300)
            assert instruments_below(p), (scene, w, lecture)
            assert_no_overflow(p, f"{scene} at {w}×{h}{' lecture' if lecture else ''}")
        sized(1280, 720)
        p.wait_for_timeout(300)
        assert_no_overflow(p, f"{scene} at 1280×720 lecture")
        page.settle()


@pytest.mark.parametrize("width,height", [(1280, 720), (1024, 768), (1920, 1080)])
def test_lecture_modes_animation_stays_beside_what_is_read(server, page, sized, width, height):
    """Lecture mode keeps the animation's column in view (sticky); it has a column of its own
    for the page's whole height, so scrolled down to the plots it sits beside them, not on them."""
    sized(width, height)
    p = page.page
    p.goto(f"{server}/scenes/spring_mass_damper?lecture=1")
    wait_ready(page)
    for panel in (".panel.plots", ".panel.work", ".col-side"):
        p.eval_on_selector(panel, "n => n.scrollIntoView()")
        p.wait_for_timeout(200)
        main, other = rect(p, ".col-main"), rect(p, panel)
        assert main["right"] <= other["left"], (panel, main, other)
        assert main["bottom"] > 0 and main["top"] < height, "the animation is still in view"
    assert_no_overflow(p, f"lecture at {width}×{height}")


def test_compare_mode_puts_the_instruments_back_under_the_canvases(server, page, sized):
    sized(1400, 900)
    p = page.page
    p.goto(f"{server}/scenes/simple_pendulum?compare=1&method_b=rk4&dt=0.01")
    wait_ready(page)
    p.wait_for_selector("#view-b:not([hidden])")
    assert instruments_below(p)


# ------------------------------------------------------------------------- 3. plot legends
@pytest.mark.timeout(400)
@pytest.mark.parametrize("width,height", [(1400, 900), (390, 844)])
def test_no_legend_covers_a_title_or_the_data(server, page, sized, width, height):
    sized(width, height)
    p = page.page
    for scene in ("spring_mass_damper", "double_pendulum", "bead_on_hoop"):
        p.goto(f"{server}/scenes/{scene}")
        wait_ready(page)
        p.evaluate(
            "document.querySelectorAll('.panel.plots details.fold, .panel.work details.fold')"
            ".forEach((d) => { d.open = true; })"
        )
        p.evaluate("document.querySelector('.panel.plots').scrollIntoView()")
        for plot in ("q", "phase", "energy", "work", "constraint"):
            p.wait_for_selector(f"#plot-{plot} .main-svg", timeout=60_000)
        p.wait_for_timeout(500)
        found = p.evaluate(OVERLAPS)
        assert {"plot-q", "plot-phase", "plot-energy", "plot-work"} <= set(found), found
        # the energies have at least T, V and E: a legend, which must be clear of everything
        assert found["plot-energy"]["legend"]
        bad = {k: v["bad"] for k, v in found.items() if v["bad"]}
        assert bad == {}, f"{scene} at {width}: {bad}"
        page.settle()


# ------------------------------------------------------------------------- 5. catalog warming
def test_catalog_shows_placeholders_and_progress_while_warming(server, context):
    p = context.new_page()
    held = []
    p.route("**/api/v1/scenes/catalog", lambda route: held.append(route))
    p.route(
        "**/healthz",
        lambda route: route.fulfill(
            status=200,
            content_type="application/json",
            body=json.dumps({"status": "ok", "version": "x", "warm": {"done": 3, "of": 14}}),
        ),
    )
    try:
        p.goto(f"{server}/")
        cards = p.locator("svg[data-thumb]").count()
        assert cards == len(api(server, "/api/v1/scenes"))
        p.wait_for_selector("#catalog-progress progress[value='3']", timeout=10_000)
        assert p.locator("svg[data-thumb][data-ready='waiting']").count() == cards
        assert p.locator("svg[data-thumb] text").first.text_content() == "preparing the drawing…"
        line = p.inner_text("#catalog-progress")
        assert "3 of 14" in line, line
        assert p.get_attribute("#catalog-progress progress", "max") == "14"
        assert p.get_attribute("svg[data-thumb]", "aria-busy") == "true"
        assert held, "the catalog was asked for"
        held[0].continue_()
        p.wait_for_function(
            "() => [...document.querySelectorAll('svg[data-thumb]')]"
            ".every((s) => s.dataset.ready === '1')",
            timeout=60_000,
        )
        assert p.locator("#catalog-progress").count() == 0
        assert p.locator("svg[data-thumb][aria-busy]").count() == 0
    finally:
        p.close()


# ------------------------------------------------------------------------- 6. editor "Start from"
def test_editor_start_from_names_a_shared_specs_scene(server, page):
    p = page.page
    spec = api(server, "/api/v1/scenes/atwood_machine")["spec"]
    link = api(server, "/api/v1/export/share", {"scene": spec, "parameters": {"m1": 2.5}})
    p.goto(f"{server}{link['url']}")
    p.wait_for_selector("#template[data-origin]", state="attached", timeout=60_000)
    page.settle(60_000)
    assert urlparse(p.url).path == "/editor"
    assert p.input_value("#template") == "atwood_machine"
    assert p.get_attribute("#template", "data-origin") == "atwood_machine"

    own = {
        "title": "My swing",
        "coordinates": ["phi"],
        "parameters": {"m": 2.0, "L": 0.7, "g": 9.81},
        "initial": {"phi": 0.4},
        "bodies": [{"name": "seat", "mass": "m", "position": ["L*sin(phi)", "-L*cos(phi)", 0]}],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }
    link = api(server, "/api/v1/export/share", {"scene": own})
    p.goto(f"{server}{link['url']}")
    p.wait_for_selector("#template[data-origin]", state="attached", timeout=60_000)
    page.settle(60_000)
    assert p.get_attribute("#template", "data-origin") == "shared"
    shown = p.eval_on_selector("#template", "s => s.selectedOptions[0].textContent")
    assert shown == "shared spec"
    # Load with "shared spec" chosen brings the shared spec back after another was loaded
    p.select_option("#template", "simple_pendulum")
    p.click("#load-template")
    p.wait_for_function("() => document.getElementById('spec').value.includes('Simple pendulum')")
    p.select_option("#template", "")
    p.click("#load-template")
    assert json.loads(p.input_value("#spec")) == own
