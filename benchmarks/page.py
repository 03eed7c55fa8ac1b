"""``python -m benchmarks page``: how fast a scene page shows its derivation and a moving
animation, and how many bytes it transfers, first visit and repeat (issue 13, item 1).

Starts the app on a free loopback port (or measures ``--url``), warms the server (every scene's
page asked for once, so derivations, compiled equations and live modules are in memory: "a warm
server"), then opens each scene in a fresh browser context ("a cold browser": empty cache) and
records, from navigation start:

- derivation: the steps are on the page (their text; MathJax may still be typesetting);
- typeset: MathJax has rendered every step;
- in view typeset: every step the reader can see is rendered, for a reader who came for the
  derivation: lecture mode on a 1280×720 projector (step 1 beside the animation), and a link to
  the derivation (``#h-derivation``) at 1400×900. On the plain page the derivation is below the
  fold; it is typeset after the animation moves, steps in view first;
- moving: the canvas has drawn two different frames of a run (a live preview or the server's);
- server run: the server's run is on the canvas;
- first visit: bytes transferred (compressed, headers included) until the page settled and its
  plots were drawn; repeat: the same page opened again in the same context;
- 'Pause' over a blank canvas: animation frames in which the button said 'Pause' before anything
  was drawn on the canvas or said there (the page's template says 'Pause' before its script runs).

Each milestone is the median of ``--runs`` passes (3 by default). ``--baseline URL`` compares
instead: a running server of the old commit against this one, visits alternating, medians and
ratios of "typeset" and "moving". Needs Playwright and Debian's
chromium (as the browser tests do). The numbers depend on the machine: on a shared 2-core box,
run it alone.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
ROOT = Path(__file__).resolve().parent.parent

#: Recorded in the page from its first script on: when each milestone was first seen.
PROBE = """
(() => {
  const seen = {};
  window.__bench = seen;
  let frame = null;
  const mark = (k) => { if (!(k in seen)) seen[k] = performance.now(); };
  const tick = () => {
    const steps = document.querySelector("#steps li.step");
    if (steps) mark("derivation");
    const list = document.querySelector("#steps");
    if (list && list.dataset.typeset === "1") mark("typeset");
    if (steps) { // every step the reader can see now is typeset
      const seen = [...document.querySelectorAll("#steps li.step")].filter((li) => {
        const r = li.getBoundingClientRect();
        return r.height > 0 && r.bottom > 0 && r.top < innerHeight;
      });
      if (seen.length && seen.every((li) => li.dataset.typeset === "1")) mark("typeset_view");
    }
    const c = document.querySelector("#canvas");
    if (c && c.dataset.frame !== undefined) {
      if (frame !== null && c.dataset.frame !== frame) mark("moving");
      frame = c.dataset.frame;
    }
    if (c && c.dataset.lastQ) mark("server_run");
    if (document.querySelector("#plot-q .main-svg")) mark("plots");
    const play = document.querySelector("#play");
    if (play && /Pause/.test(play.textContent) && c && !c.dataset.source && !c.dataset.waiting) {
      seen.blank_while_pause = (seen.blank_while_pause || 0) + 1;
    }
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
})();
"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def _server() -> Iterator[str]:
    port = _free_port()
    env = {**os.environ}
    env.setdefault("LAGRANGE_LAB_CACHE", tempfile.mkdtemp(prefix="bench-page-"))
    cmd = [sys.executable, "-m", "uvicorn", "app.main:app", "--port", str(port)]
    proc = subprocess.Popen([*cmd, "--log-level", "warning"], cwd=ROOT, env=env)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 120
        while True:
            try:
                urllib.request.urlopen(f"{url}/healthz", timeout=1)
                break
            except OSError:
                if time.monotonic() > deadline or proc.poll() is not None:
                    raise RuntimeError("the server did not start") from None
                time.sleep(0.2)
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


def _settle(page, timeout: float = 120_000) -> None:
    page.wait_for_function(
        "() => (document.documentElement.dataset.pending || '0') === '0'"
        " && window.__bench && 'server_run' in window.__bench && 'typeset' in window.__bench"
        " && 'plots' in window.__bench",
        timeout=timeout,
    )
    page.wait_for_timeout(300)  # late resources (fonts MathJax asks for)


def _visit(context, url: str) -> tuple[dict, int, int]:
    """One navigation: the milestones (ms) and the bytes transferred, and the request count."""
    page = context.new_page()
    cdp = context.new_cdp_session(page)
    cdp.send("Network.enable")
    sizes: dict[str, int] = {}
    cdp.on(
        "Network.loadingFinished",
        lambda e: sizes.__setitem__(e["requestId"], e["encodedDataLength"]),
    )
    page.goto(url)
    _settle(page)
    marks = page.evaluate("() => window.__bench")
    page.close()
    return marks, sum(sizes.values()), len(sizes)


#: Milestones (ms) reported as the median over the runs; the rest are from the first run, but
#: blank frames, where any run counts (the worst is what a student may see).
TIMES = (
    "derivation",
    "typeset",
    "moving",
    "server_run",
    "lecture_view",
    "lecture_moving",
    "linked_view",
    "linked_moving",
)


def _median(values: list) -> float | None:
    known = sorted(v for v in values if v is not None)
    return statistics.median(known) if known else None


def measure(url: str, scenes: list[str], runs: int = 1) -> list[dict]:
    """Each scene's row; with several runs, the median of each milestone, because one pass on a
    shared 2-core machine can be off by 0.1–0.2 s on either side of the 1.0 s target."""
    passes = [_measure(url, scenes) for _ in range(max(1, runs))]
    rows = []
    for i, first in enumerate(passes[0]):
        row = dict(first)
        for key in TIMES:
            row[key] = _median([p[i][key] for p in passes])
        row["blank_while_pause"] = max(p[i]["blank_while_pause"] for p in passes)
        rows.append(row)
    return rows


def _measure(url: str, scenes: list[str]) -> list[dict]:
    from playwright.sync_api import sync_playwright

    rows = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=["--no-sandbox"])
        try:
            for scene in scenes:  # warm the server: what the page asks for, once
                ctx = browser.new_context(bypass_csp=True)
                ctx.add_init_script(PROBE)
                _visit(ctx, f"{url}/scenes/{scene}")
                ctx.close()
            for scene in scenes:
                ctx = browser.new_context(viewport={"width": 1400, "height": 900}, bypass_csp=True)
                ctx.add_init_script(PROBE)
                first, first_bytes, first_n = _visit(ctx, f"{url}/scenes/{scene}")
                _, repeat_bytes, repeat_n = _visit(ctx, f"{url}/scenes/{scene}")
                ctx.close()
                ctx = browser.new_context(viewport={"width": 1280, "height": 720}, bypass_csp=True)
                ctx.add_init_script(PROBE)
                lecture, _, _ = _visit(ctx, f"{url}/scenes/{scene}?lecture=1")
                ctx.close()
                ctx = browser.new_context(viewport={"width": 1400, "height": 900}, bypass_csp=True)
                ctx.add_init_script(PROBE)
                linked, _, _ = _visit(ctx, f"{url}/scenes/{scene}#h-derivation")
                ctx.close()
                rows.append(
                    {
                        "scene": scene,
                        **{
                            k: first.get(k)
                            for k in ("derivation", "typeset", "moving", "server_run")
                        },
                        "lecture_view": lecture.get("typeset_view"),
                        "lecture_moving": lecture.get("moving"),
                        "linked_view": linked.get("typeset_view"),
                        "linked_moving": linked.get("moving"),
                        "blank_while_pause": first.get("blank_while_pause", 0),
                        "first_kB": first_bytes / 1000,
                        "first_requests": first_n,
                        "repeat_kB": repeat_bytes / 1000,
                        "repeat_requests": repeat_n,
                    }
                )
        finally:
            browser.close()
    return rows


def table(rows: list[dict]) -> str:
    head = (
        "| scene | derivation (ms) | typeset, every step (ms) | moving (ms) | server run (ms) | "
        "lecture: in view typeset / moving (ms) | #h-derivation: in view typeset / moving (ms) | "
        "first visit (kB, requests) | repeat (kB, requests) | 'Pause' over a blank canvas |"
    )
    lines = [head, "|" + "---|" * 10]

    def ms(v):
        return "–" if v is None else f"{v:.0f}"

    for r in rows:
        lines.append(
            f"| {r['scene']} | {ms(r['derivation'])} | {ms(r['typeset'])} | {ms(r['moving'])} | "
            f"{ms(r['server_run'])} | {ms(r['lecture_view'])} / {ms(r['lecture_moving'])} | "
            f"{ms(r['linked_view'])} / {ms(r['linked_moving'])} | "
            f"{r['first_kB']:.0f} ({r['first_requests']}) | "
            f"{r['repeat_kB']:.1f} ({r['repeat_requests']}) | {r['blank_while_pause']} frames |"
        )
    return "\n".join(lines)


def side_by_side(urls: list[str], scenes: list[str], runs: int) -> str:
    """Did a change make the page faster? One pass on a shared machine cannot say. Two servers
    (the baseline first) measured in one browser, a fresh context per visit, alternating visit
    by visit so that a machine's changing load falls on both alike; medians and their ratio."""
    from playwright.sync_api import sync_playwright

    keys = ("typeset", "moving")
    seen = {(u, sc): {k: [] for k in keys} for u in urls for sc in scenes}
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=["--no-sandbox"])
        try:
            for url in urls:  # warm both servers
                for scene in scenes:
                    ctx = browser.new_context(bypass_csp=True)
                    ctx.add_init_script(PROBE)
                    _visit(ctx, f"{url}/scenes/{scene}")
                    ctx.close()
            for i in range(runs):
                for scene in scenes:
                    for url in urls if i % 2 == 0 else urls[::-1]:
                        ctx = browser.new_context(
                            viewport={"width": 1400, "height": 900}, bypass_csp=True
                        )
                        ctx.add_init_script(PROBE)
                        marks, _, _ = _visit(ctx, f"{url}/scenes/{scene}")
                        ctx.close()
                        for k in keys:
                            seen[url, scene][k].append(marks.get(k))
        finally:
            browser.close()
    base, new = urls
    lines = [
        "| scene | typeset, every step: baseline / new (ms) | ratio | "
        "moving: baseline / new (ms) | ratio |",
        "|---|---|---|---|---|",
    ]
    for scene in scenes:
        cells = []
        for k in keys:
            a, b = _median(seen[base, scene][k]), _median(seen[new, scene][k])
            ratio = "–" if not a or b is None else f"{b / a:.2f}"
            cells.append(f"{a:.0f} / {b:.0f} | {ratio}" if a and b else "– | –")
        lines.append(f"| {scene} | {' | '.join(cells)} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", help="measure a running server instead of starting one")
    parser.add_argument("--scenes", help="comma-separated scene ids (default: every scene)")
    parser.add_argument(
        "--runs", type=int, default=3, help="passes over the scenes; milestones are medians"
    )
    parser.add_argument(
        "--baseline",
        metavar="URL",
        help="a running server to compare with, side by side (the one measured is --url, or "
        "this checkout's, started here): typeset and moving, medians of --runs visits each",
    )
    args = parser.parse_args(argv)
    from mechanics.scenes import scene_ids

    scenes = args.scenes.split(",") if args.scenes else scene_ids()
    if args.baseline:
        with contextlib.ExitStack() as stack:
            url = args.url.rstrip("/") if args.url else stack.enter_context(_server())
            print(side_by_side([args.baseline.rstrip("/"), url], scenes, max(2, args.runs)))
        return
    if args.url:
        print(table(measure(args.url.rstrip("/"), scenes, args.runs)))
        return
    with _server() as url:
        print(table(measure(url, scenes, args.runs)))


if __name__ == "__main__":
    main()
