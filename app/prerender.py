"""``python -m app.prerender``: typeset every built-in derivation ahead of time.

MathJax took 0.4–0.9 s of a scene page's main thread to typeset a derivation that is the same on
every visit (issue 13). This runs the pages once in Chromium, with the page's own MathJax and
configuration, and keeps what MathJax made of each formula in ``static/math/<scene>.json``; the
pages then put those equations up as they are (static/js/prerendered.js). Each formula is keyed
by its exact TeX and the font size it was typeset at (MathJax's smallest script size is in
pixels, so a subscript of a subscript is drawn a little differently at 16 px and at lecture
mode's 24 px), so a file older than the derivation only misses (that formula is typeset live);
``tests/pages/test_prerendered_files.py`` fails when a file no longer covers its derivation, and
``tests/browser/test_prerendered_math.py`` when a formula renders differently live.

The pages are read at the sizes the room uses (a laptop, lecture mode on three projectors, a
phone), since a wide equation is broken into lines differently at each (static/js/fit.js), and
every form it takes is kept. Needs Chromium and Playwright (the test extra): a build step for
whoever changes a derivation's text, not something a server does.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

from app.paths import STATIC_DIR

CHROMIUM = "/usr/bin/chromium"
SVG_NS = "http://www.w3.org/2000/svg"
#: (width, height, query): a laptop, lecture mode with every step shown on three projectors, a phone
VIEWS = (
    (1280, 800, ""),
    (1024, 768, "?lecture=1&step=99"),
    (1280, 720, "?lecture=1&step=99"),
    (1920, 1080, "?lecture=1&step=99"),
    (390, 844, ""),
)

#: Every formula MathJax typeset in the steps: its key (D or I, then the TeX) and its container,
#: without what the page added after (the menu's marks, the scroll cue's class), and the glyphs.
HARVEST = r"""() => {
  const math = {};
  for (const m of MathJax.startup.document.math) {
    const root = m.typesetRoot;
    if (!root || !root.isConnected || !root.closest('#steps')) continue;
    const copy = root.cloneNode(true);
    copy.removeAttribute('ctxtmenu_counter');
    copy.setAttribute('class', 'MathJax');
    const px = +parseFloat(getComputedStyle(root.parentElement).fontSize).toFixed(2);
    math[`${m.display ? 'D' : 'I'}${px}|${m.math}`] = copy.outerHTML;
  }
  const glyphs = {};
  const cache = document.getElementById('MJX-SVG-global-cache');
  if (cache) for (const g of cache.querySelectorAll('defs > [id]')) glyphs[g.id] = g.outerHTML;
  const css = document.getElementById('MJX-SVG-styles')?.textContent || '';
  return {math, glyphs, css, version: MathJax.version};
}"""


def _serve(port: int) -> subprocess.Popen:
    env = dict(os.environ, LAGRANGE_LAB_CACHE=tempfile.mkdtemp(prefix="lagrange-prerender-"))
    proc = subprocess.Popen(
        [sys.executable, "-m", "app", "serve", "--port", str(port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 120
    while True:
        try:
            urllib.request.urlopen(f"http://127.0.0.1:{port}/healthz", timeout=1)
            return proc
        except OSError:
            if time.monotonic() > deadline or proc.poll() is not None:
                proc.kill()
                raise SystemExit("the server did not start") from None
            time.sleep(0.3)


def _settled(page) -> None:
    """Wait until the steps are typeset and fitted: no request in flight and MathJax's list of
    formulas unchanged for a while (fitting a wide equation typesets its broken form later)."""
    page.wait_for_selector('#steps[data-typeset="1"]', timeout=120_000)
    last, steady = -1, 0
    deadline = time.monotonic() + 60
    while steady < 4 and time.monotonic() < deadline:
        page.wait_for_timeout(250)
        now = page.evaluate(
            "(window.MathJax?.startup?.document?.math?.toArray?.() || []).length"
            " + (document.documentElement.dataset.pending === '0' ? 0 : 1e6)"
        )
        steady = steady + 1 if now == last else 0
        last = now


def harvest(url: str, scenes: list[str]) -> dict[str, dict]:
    """Each scene's formulas and glyphs, from its pages at every size in VIEWS."""
    from playwright.sync_api import sync_playwright

    found: dict[str, dict] = {}
    with sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=CHROMIUM if Path(CHROMIUM).exists() else None,
            headless=True,
            args=["--no-sandbox", "--disable-gpu"],
        )
        for scene in scenes:
            math: dict[str, str] = {}
            glyphs: dict[str, str] = {}
            version, css = None, ""
            for width, height, query in VIEWS:
                context = browser.new_context(viewport={"width": width, "height": height})
                page = context.new_page()
                # the page must typeset everything live: an older file would hide formulas
                page.route(re.compile(r".*/math/[^/]+\.json$"), lambda route: route.abort())
                page.goto(f"{url}/scenes/{scene}{query}")
                _settled(page)
                got = page.evaluate(HARVEST)
                context.close()
                math.update(got["math"])
                glyphs.update(got["glyphs"])
                version = got["version"]
                css = max(css, got["css"], key=len)  # the rules MathJax's output needs
            found[scene] = {"math": math, "glyphs": glyphs, "css": css, "mathjax": version}
            print(f"{scene}: {len(math)} formulas, {len(glyphs)} glyphs", flush=True)
        browser.close()
    return found


def write(found: dict[str, dict], folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for scene, got in found.items():
        defs = "".join(got["glyphs"][k] for k in sorted(got["glyphs"]))
        # most formulas render alike at every size: each rendering is stored once
        html: list[str] = []
        index: dict[str, int] = {}
        keys = {}
        for key, rendered in sorted(got["math"].items()):
            keys[key] = index.setdefault(rendered, len(html))
            if keys[key] == len(html):
                html.append(rendered)
        data = {
            "mathjax": got["mathjax"],
            "css": got["css"],
            "defs": f'<svg xmlns="{SVG_NS}" style="display: none;"><defs>{defs}</defs></svg>',
            "math": keys,
            "html": html,
        }
        text = json.dumps(data, ensure_ascii=False, separators=(",", ":"), sort_keys=False)
        (folder / f"{scene}.json").write_text(text + "\n", encoding="utf-8")


def main(argv: list[str] | None = None) -> None:
    from mechanics.scenes import scene_ids

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", help="comma-separated scene ids (default: every scene)")
    parser.add_argument("--url", help="read the pages of a running server instead of starting one")
    args = parser.parse_args(argv)
    scenes = args.scenes.split(",") if args.scenes else list(scene_ids())
    proc = None
    url = args.url
    if url is None:
        import socket

        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        proc = _serve(port)
        url = f"http://127.0.0.1:{port}"
    try:
        write(harvest(url, scenes), STATIC_DIR / "math")
    finally:
        if proc is not None:
            proc.terminate()
            proc.wait(timeout=10)


if __name__ == "__main__":
    main()
