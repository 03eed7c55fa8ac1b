"""The pages fit their screen: a projector in lecture mode (1024×768, 1280×720, 1920×1080) and a
phone (390×844).

What "fits" means here, measured in the browser rather than taken from the stylesheet:
- the page is no wider than the window (``scrollingElement.scrollWidth <= innerWidth``), and no
  visible element's right edge lies beyond it, except inside a box that scrolls on purpose;
- a display equation wider than its box is inside a box marked ``scrolls`` (the visible cue);
- in lecture mode, no equation of the derivation scrolls at all (each is broken into lines or
  scaled to fit), every piece of text outside drawings (svg, canvas, plots, typeset math) is at
  least 24 px, the size the issue asks for the back of a hall, and → / space / PageDown still
  reveal one more step each;
- on a phone, every panel but the animation can be folded (a <details> with a summary).
"""

from __future__ import annotations

import json
import re
import urllib.request
from pathlib import Path

import pytest
from lecture_keys import press, reveal_all

pytestmark = pytest.mark.browser

LECTURE_SIZES = [(1024, 768), (1280, 720), (1920, 1080)]
PHONE = (390, 844)


def scene_ids(server: str) -> list[str]:
    with urllib.request.urlopen(f"{server}/api/v1/scenes") as r:
        return [s["id"] for s in json.load(r)]


@pytest.fixture(scope="module")
def scenes(server) -> list[str]:
    return scene_ids(server)


# Elements whose right edge lies beyond the window, not counting those inside a box that clips or
# scrolls (overflow-x other than visible) narrower than the window, nor hidden ones.
OVERFLOWING = """() => {
  const W = document.documentElement.clientWidth;
  const clipped = (el) => {
    for (let p = el.parentElement; p && p !== document.body; p = p.parentElement) {
      const o = getComputedStyle(p).overflowX;
      if (o !== "visible" && p.getBoundingClientRect().right <= W + 1) return true;
    }
    return false;
  };
  const out = [];
  for (const el of document.querySelectorAll("body *")) {
    const r = el.getBoundingClientRect();
    if (!r.width || r.right <= W + 1 || getComputedStyle(el).visibility === "hidden") continue;
    if (el.closest(".skip-link") || clipped(el)) continue;
    const name = `${el.tagName.toLowerCase()}#${el.id}.${String(el.className).slice(0, 40)}`;
    out.push(`${name} right=${Math.round(r.right)}`);
  }
  const width = innerWidth;
  return { scrollWidth: document.scrollingElement.scrollWidth, width, over: out.slice(0, 10) };
}"""

# Display equations wider than their box that carry no scroll cue.
UNCUED = """() => {
  const out = [];
  const wide = (b) => b.scrollWidth > b.clientWidth + 1;
  for (const m of document.querySelectorAll(".math")) {
    if (m.offsetParent === null || !wide(m)) continue;
    if (!m.classList.contains("scrolls")) out.push(m.dataset.latex.slice(0, 60));
  }
  for (const m of document.querySelectorAll('mjx-container[display="true"]')) {
    if (m.closest(".math") || m.offsetParent === null) continue;
    if (wide(m) && !m.classList.contains("scrolls")) out.push(m.textContent.slice(0, 60));
  }
  return out;
}"""

# Text smaller than `min` px: elements with their own visible text, outside drawings and math (and
# sub- and superscripts, smaller by typographic convention).
SMALL_TEXT = """(min) => {
  const out = [];
  const skip = "svg, canvas, mjx-container, .plot, .skip-link, script, style, option, sub, sup";
  for (const el of document.querySelectorAll("main *, .topbar *")) {
    if (el.closest(skip) || el.offsetParent === null) continue;
    const own = [...el.childNodes].some((n) => n.nodeType === 3 && n.textContent.trim());
    const control = el.matches("button, select, input, output, label, summary");
    if (!own && !control) continue;
    const size = parseFloat(getComputedStyle(el).fontSize);
    if (size >= min - 0.01) continue;
    const name = `${el.tagName.toLowerCase()}.${String(el.className).slice(0, 30)}`;
    out.push(`${name} ${size}px: ${el.textContent.trim().slice(0, 30)}`);
  }
  return out.slice(0, 12);
}"""

# Every visible .math box has been fitted at its current width (fit.js records it).
FITTED = """() => [...document.querySelectorAll("#steps .math")]
  .filter((m) => m.offsetParent !== null)
  .every((m) => m.dataset.fitWidth === String(m.clientWidth))"""


def script_errors(page) -> list[str]:
    """The page's own exceptions (a busy server's 503 under a loaded test machine is not one)."""
    return [e for e in page.errors if e.startswith("page error")]


def open_scene(p, server: str, scene: str, query: str = "") -> None:
    p.goto(f"{server}/scenes/{scene}{query}")
    p.wait_for_function(
        "() => document.getElementById('steps').dataset.typeset === '1'", timeout=90_000
    )


def assert_fits(p, where: str) -> None:
    p.wait_for_function(FITTED, timeout=30_000)
    m = p.evaluate(OVERFLOWING)
    assert m["scrollWidth"] <= m["width"], f"{where}: page {m['scrollWidth']} px wide: {m['over']}"
    assert not m["over"], f"{where}: beyond the right edge: {m['over']}"
    assert p.evaluate(UNCUED) == [], f"{where}: wide equations without a scroll cue"


@pytest.mark.timeout(600)  # every built-in scene, one after another
def test_lecture_mode_fits_the_projector_on_every_scene(server, page, sized, scenes):
    p = page.page
    for scene in scenes:
        sized(*LECTURE_SIZES[0])
        open_scene(p, server, scene, "?lecture=1")
        reveal_all(p)
        for w, h in LECTURE_SIZES:
            sized(w, h)
            where = f"{scene} at {w}×{h}"
            assert_fits(p, where)
            # on a projector no equation is left to scroll: each is broken or scaled to fit
            scrolling = p.evaluate(
                "[...document.querySelectorAll('#steps .math.scrolls')].map((m) => m.dataset.latex)"
            )
            assert scrolling == [], f"{where}: equations that still scroll: {scrolling}"
            small = p.evaluate(SMALL_TEXT, 24)
            assert not small, f"{where}: text under 24 px: {small}"
        page.settle()  # no run in flight when the next scene is opened
    assert not script_errors(page)


def test_lecture_keys_reveal_one_step_each(server, page, sized):
    p = page.page
    sized(1280, 720)
    open_scene(p, server, "double_pendulum", "?lecture=1")
    revealed = lambda: int(p.evaluate("document.getElementById('steps').dataset.revealed"))  # noqa: E731
    assert revealed() == 1
    # each key moves on: a screen further through a step taller than the screen, else one step
    for key in ["ArrowRight", " ", "PageDown"] * 3:
        before = (revealed(), p.evaluate("scrollY"))
        press(p, key)
        after = (revealed(), p.evaluate("scrollY"))
        assert after[0] == before[0] + 1 or (after[0] == before[0] and after[1] > before[1])
    reached = revealed()
    assert reached >= 3
    for _ in range(10):  # ← goes back the same way, and hides the steps again
        press(p, "ArrowLeft")
    assert revealed() < reached
    # the derivation sits beside the animation, and so it comes right after it in the page
    order = p.evaluate(
        "[...document.querySelector('.scene-layout').children].map((c) => c.className)"
    )
    assert order[0].startswith("col-main") and "derivation" in order[1], order


@pytest.mark.parametrize("path", ["/", "/editor"])
def test_phone_catalog_and_editor_fit(server, page, sized, path):
    p = page.page
    sized(*PHONE)
    p.goto(f"{server}{path}")
    p.wait_for_load_state("load")
    assert_fits_page(p, path)


def assert_fits_page(p, where: str) -> None:
    m = p.evaluate(OVERFLOWING)
    assert m["scrollWidth"] <= m["width"], f"{where}: page {m['scrollWidth']} px wide: {m['over']}"
    assert not m["over"], f"{where}: beyond the right edge: {m['over']}"


@pytest.mark.timeout(600)  # every built-in scene, one after another
def test_phone_every_scene_fits_and_folds(server, page, sized, scenes):
    p = page.page
    sized(*PHONE)
    for scene in scenes:
        open_scene(p, server, scene)
        # open every fold, so what a student can open is measured too
        p.evaluate("document.querySelectorAll('details.fold').forEach((d) => { d.open = true; })")
        assert_fits(p, f"{scene} on a phone")
        unfoldable = p.evaluate(
            """[...document.querySelectorAll('main section.panel')]
                 .filter((s) => !s.classList.contains('stage'))
                 .filter((s) => !s.querySelector(':scope > details > summary, [aria-expanded]'))
                 .map((s) => s.className)"""
        )
        assert unfoldable == [], f"{scene}: sections that cannot be folded: {unfoldable}"
        page.settle()
    # a phone starts with the secondary panels folded
    open_scene(p, server, scenes[0])
    closed = p.evaluate(
        "[...document.querySelectorAll('details.fold:not([open])')]"
        ".map((d) => d.parentElement.className)"
    )
    assert any("plots" in c for c in closed) and any("integrator" in c for c in closed), closed
    assert not script_errors(page)


# ---------------------------------------------------------------- breaking equations (fit.js)
FIT_JS = Path(__file__).resolve().parents[2] / "static" / "js" / "fit.js"


def _normal(tex: str) -> str:
    """LaTeX with the layout of a broken line taken out: what is left is the mathematics."""
    for layout in (r"\begin{aligned}", r"\end{aligned}", "&", r"\\", r"\quad"):
        tex = tex.replace(layout, "")
    tex = tex.replace(r"\Bigl(", r"\left(").replace(r"\Bigr)", r"\right)")
    return "".join(tex.split())


def _rows(broken: str) -> list[str]:
    inner = broken.removeprefix(r"\begin{aligned}").removesuffix(r"\end{aligned}")
    return inner.split(r" \\ ")


def _check_broken(tex: str, broken: str) -> None:
    """A broken line says what the engine's line says: the same terms in the same order, a matrix
    entry by entry, a fraction as num/den with num and den the original's."""
    matrix = re.fullmatch(r"(.+?) = \\left\[\\begin\{matrix\}(.*)\\end\{matrix\}\\right\]", tex)
    if matrix:
        name, body = matrix.groups()
        cells = [[c.strip() for c in row.split("&")] for row in body.split(r"\\")]
        column = all(len(r) == 1 for r in cells)
        text = _normal(broken)
        for j, row in enumerate(cells, start=1):
            for k in range(1, len(row) + 1):
                sub = f"{j}" if column else f"{j}{k}"
                assert _normal(f"{name}_{{{sub}}}=") in text
        entries = re.split(r"\\mathbf\{\w\}_\{\d+\}=", text)[1:]
        assert [_normal(c) for row in cells for c in row] == entries
        return
    if r"\text{num}" in broken:
        text = _normal(broken)
        lhs, rest = text.split(r"=\frac{\text{num}}{\text{den}}")
        num, den = rest.removeprefix(r"\text{num}=").split(r"\text{den}=")
        assert _normal(tex) == f"{lhs}=\\frac{{{num}}}{{{den}}}"
        return
    assert _normal(broken) == _normal(tex)
    assert len(_rows(broken)) >= 2


def test_broken_equations_say_what_the_engine_wrote(server):
    """Every long line of three derivations, broken into 2, 3 and 5 lines, with and without
    opening brackets, is the same mathematics (run by node on fit.js itself)."""
    import shutil
    import subprocess

    if not shutil.which("node"):
        pytest.skip("node is not installed")
    lines = []
    for scene in ("double_pendulum", "cart_pendulum", "incline_friction"):
        request = urllib.request.Request(
            f"{server}/api/v1/derive",
            data=json.dumps({"scene_id": scene}).encode(),
            headers={"content-type": "application/json"},
        )
        with urllib.request.urlopen(request, timeout=120) as r:
            lines += [tex for step in json.load(r)["steps"] for tex in step["latex"]]
    long = [tex for tex in lines if len(tex) > 120]
    assert len(long) >= 10
    script = (
        "globalThis.window = {};\n"
        f"const {{ breakLine }} = await import({json.dumps(str(FIT_JS))});\n"
        "const lines = JSON.parse(process.argv[1]);\n"
        "const out = lines.map((t) => [2, 3, 5].flatMap((n) => [false, true]"
        ".map((fine) => breakLine(t, n, fine))));\n"
        "console.log(JSON.stringify(out));\n"
    )
    done = subprocess.run(
        ["node", "--input-type=module", "-e", script, json.dumps(long)],
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    broken_any = 0
    for tex, variants in zip(long, json.loads(done.stdout), strict=True):
        for broken in variants:
            if broken is None:
                continue
            broken_any += 1
            _check_broken(tex, broken)
    assert broken_any >= 5 * len(long) // 2


#: Controls (sliders, number boxes, labels) whose right edge crosses their card's inner edge.
CONTROLS_PAST_THEIR_CARD = """() => {
  const out = [];
  for (const el of document.querySelectorAll('#params .control > *, #initial .control > *')) {
    const card = el.closest('section, .card, details');
    if (!card || !el.getClientRects().length) continue;
    const box = card.getBoundingClientRect();
    const pad = parseFloat(getComputedStyle(card).paddingRight) || 0;
    const right = el.getBoundingClientRect().right;
    const edge = box.right - pad;
    const name = el.id || el.tagName;
    if (right > edge + 0.5) out.push(`${name}: ${right.toFixed(0)} > ${edge.toFixed(0)}`);
  }
  return out;
}"""


@pytest.mark.parametrize(
    ("size", "query"), [((1024, 768), ""), ((1024, 768), "?lecture=1"), ((390, 844), "")]
)
def test_the_number_boxes_stay_inside_their_card(server, page, sized, size, query):
    """At 1024 px the initial-state boxes of the double pendulum stuck 20 px out of the
    Parameters card (the names with _dot set the label column) and the sliders shrank to 70 px
    (student play-test); on a phone 3 px."""
    p = page.page
    sized(*size)
    for scene in ("double_pendulum", "spherical_pendulum", "cart_pendulum"):
        open_scene(p, server, scene, query)
        p.wait_for_selector("#initial input[type=number]")
        over = p.evaluate(CONTROLS_PAST_THEIR_CARD)
        assert over == [], f"{scene} at {size}{query}: {over}"
    assert not script_errors(page)
