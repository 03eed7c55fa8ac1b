"""The app installs like any Python web app: a wheel built from the repo, installed in a fresh venv
outside the checkout, serves every page, its assets and the API docs, offline, under its CSP.

The venv sees the machine's packages (``--system-site-packages``): the dependencies come from
there and nothing is downloaded but what ``pip wheel`` needs to build.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from urllib.parse import urlparse

import pytest
from servers import free_port, serving

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = "/usr/bin/chromium"
#: What a wheel is built from (copied, so the build never writes into the shared checkout).
SOURCES = ["pyproject.toml", "README.md", "app", "mechanics", "templates", "static"]

pytestmark = [pytest.mark.slow, pytest.mark.timeout(600)]


def _run(*command: str | Path, cwd: Path) -> None:
    done = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"{command}:\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> str:
    """The URL of ``lagrange-lab serve`` run from a wheel installed in a fresh venv."""
    work = tmp_path_factory.mktemp("install")
    source = work / "source"
    for name in SOURCES:
        if (ROOT / name).is_dir():
            ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.so")
            shutil.copytree(ROOT / name, source / name, ignore=ignore)
        else:
            source.mkdir(exist_ok=True)
            shutil.copy2(ROOT / name, source / name)
    _run(
        sys.executable,
        "-m",
        "pip",
        "wheel",
        "--no-deps",
        "-q",
        "-w",
        work / "dist",
        ".",
        cwd=source,
    )
    (wheel,) = (work / "dist").glob("lagrange_lab-*.whl")
    venv = work / "venv"
    _run(sys.executable, "-m", "venv", "--system-site-packages", venv, cwd=work)
    python = venv / "bin" / "python"
    _run(python, "-m", "pip", "install", "-q", "--no-deps", "--no-index", wheel, cwd=work)
    shutil.rmtree(source)  # nothing left to find by a path relative to a checkout

    home = work / "elsewhere"
    home.mkdir()
    where = subprocess.run(
        [python, "-c", "import app.paths as p; print(p.TEMPLATES_DIR); print(p.STATIC_DIR)"],
        cwd=home,
        env={**os.environ, "PYTHONPATH": ""},  # a checkout on the path is not what is installed
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    assert all(Path(w).is_relative_to(venv) for w in where), where

    port = free_port()
    env = {**os.environ, "LAGRANGE_LAB_CACHE": str(work / "cache"), "PYTHONPATH": ""}
    command = [venv / "bin" / "lagrange-lab", "serve", "--port", str(port)]
    popen = {"cwd": home, "env": env, "stderr": subprocess.DEVNULL}
    with serving(command, port, what="the installed server", **popen) as (url, _):
        yield url


def _get(url: str) -> tuple[int, bytes]:
    with urllib.request.urlopen(url, timeout=60) as r:
        return r.status, r.read()


def test_the_installed_wheel_serves_pages_assets_docs_and_health(installed):
    status, page = _get(f"{installed}/scenes/double_pendulum")
    assert status == 200
    for path in ["/", "/editor", "/docs", "/redoc", "/healthz", "/static/css/app.css"]:
        assert _get(installed + path)[0] == 200, path
    assets = re.findall(r'(?:src|href)="(/static/[^"]+)"|from "(/static/[^"]+)"', page.decode())
    assert len(assets) >= 4  # css, MathJax, plotly, the page's module
    for url in (a or b for a, b in assets):
        assert _get(installed + url)[0] == 200, url


@pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian's chromium is not installed")
def test_the_installed_pages_work_offline_under_their_csp(installed):
    """A browser that enforces the CSP (no bypass): the docs list the operations, a scene page
    typesets its math and plots, and nothing is refused, failed or fetched from elsewhere."""
    problems: list[str] = []
    # a thread of its own: the session's browser fixture keeps Playwright's event loop running
    # in the main thread, where a second sync_playwright() refuses to start
    with ThreadPoolExecutor(1) as pool:
        pool.submit(_browse_installed, installed, problems).result()
    assert problems == []


def _browse_installed(installed: str, problems: list[str]) -> None:
    from playwright.sync_api import sync_playwright

    host = urlparse(installed).netloc
    with sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=CHROMIUM, headless=True, args=["--no-sandbox", "--disable-gpu"]
        )
        page = browser.new_page()
        page.on("console", lambda m: m.type == "error" and problems.append(m.text))
        page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
        page.on(
            "request",
            lambda r: (
                urlparse(r.url).scheme in ("http", "https")
                and urlparse(r.url).netloc != host
                and problems.append(f"off-site request: {r.url}")
            ),
        )
        page.goto(f"{installed}/docs")
        page.locator(".opblock-summary-path").first.wait_for(timeout=30_000)
        operations = page.locator(".opblock-summary-path").all_inner_texts()
        assert {"/api/v1/derive", "/api/v1/simulate", "/api/v1/check"} <= set(operations)

        page.goto(f"{installed}/scenes/double_pendulum")
        page.locator("mjx-container svg").first.wait_for(timeout=60_000)
        page.locator(".js-plotly-plot").first.wait_for(timeout=60_000)
        page.wait_for_function(
            "() => (document.documentElement.dataset.pending || '0') === '0'", timeout=60_000
        )
        page.goto(f"{installed}/")
        page.locator("svg[data-thumb] *").first.wait_for(timeout=30_000)
        browser.close()
