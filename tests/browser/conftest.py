"""A real server and Debian's Chromium, driven by Playwright, for tests that use the pages.

One server and one browser for the whole session; one page, reused by every test, with its
console errors, failed requests and requests to other hosts collected (the pages must work
offline: MathJax and plotly come from the app).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from urllib.parse import urlparse

import pytest
from servers import free_port, serving

CHROMIUM = "/usr/bin/chromium"
ARTIFACTS = Path(__file__).resolve().parent.parent / "artifacts"
ROOT = Path(__file__).resolve().parents[2]

if not Path(CHROMIUM).exists():  # CI installs it; a bare laptop skips with a reason
    pytest.skip(
        "Debian's chromium is not installed (apt-get install chromium)", allow_module_level=True
    )


@pytest.fixture(scope="session")
def server() -> str:
    """The app under uvicorn in a subprocess. Its derivation cache is the test session's own folder
    (tests/conftest.py), so a scene another worker or test already derived is not derived again."""
    port = free_port()
    env = dict(os.environ)
    command = [sys.executable, "-m", "uvicorn", "app.main:app", "--port", str(port)]
    with serving([*command, "--log-level", "warning"], port, env=env, cwd=ROOT) as (url, _):
        yield url


@pytest.fixture(scope="session")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(
            executable_path=CHROMIUM,
            headless=True,
            args=[
                "--no-sandbox",
                "--disable-gpu",
                "--disable-background-networking",
                "--disable-component-update",
                "--no-first-run",
                "--disable-sync",
            ],
        )
        yield b
        b.close()


@pytest.fixture
def fresh(browser):
    """A context of its own: an empty cache, like a student's first visit (its CSP bypassed for
    Playwright's polling and init scripts only)."""
    ctx = browser.new_context(viewport={"width": 1300, "height": 900}, bypass_csp=True)
    yield ctx
    ctx.close()


class Watched:
    """A page with its console errors, failed requests and off-site requests collected."""

    def __init__(self, page, origin: str) -> None:
        self.page = page
        self.errors: list[str] = []
        host = urlparse(origin).netloc
        page.on("console", lambda m: m.type == "error" and self.errors.append(m.text))
        page.on("pageerror", lambda e: self.errors.append(f"page error: {e}"))
        page.on("requestfailed", self._failed)
        page.on(
            "request",
            lambda r: (
                urlparse(r.url).scheme in ("http", "https")
                and urlparse(r.url).netloc != host
                and self.errors.append(f"off-site request: {r.url}")
            ),
        )

    def _failed(self, request) -> None:
        # An API request the page cancelled itself (a run or an equilibria search superseded by
        # a newer one: its AbortController) is the page working, not an error.
        if "ERR_ABORTED" in str(request.failure) and "/api/" in request.url:
            return
        self.errors.append(f"request failed: {request.url} ({request.failure})")

    def open_paused(self, url: str) -> None:
        """Open a scene page, wait for its server run, and pause the animation on it."""
        p = self.page
        p.goto(url)
        p.wait_for_function("document.querySelector('#canvas').dataset.lastQ", timeout=90_000)
        self.settle()
        if p.get_attribute("#play", "aria-pressed") != "false":
            p.click("#play")
        p.wait_for_timeout(150)

    def settle(self, timeout: float = 60_000) -> None:
        """Wait until no API request is in flight (before leaving or reloading the page)."""
        self.page.wait_for_function(
            "() => (document.documentElement.dataset.pending || '0') === '0'", timeout=timeout
        )


@pytest.fixture(scope="session")
def context(browser, server):
    # Playwright polls a wait_for_function given as an expression string with eval, which the
    # pages' CSP rightly forbids; the pages under their CSP are tested in tests/test_install.py.
    ctx = browser.new_context(viewport={"width": 1300, "height": 900}, bypass_csp=True)
    ctx.grant_permissions(["clipboard-read", "clipboard-write"], origin=server)
    yield ctx
    ctx.close()


@pytest.fixture(scope="session")
def _session_page(context, server):
    return Watched(context.new_page(), server)


@pytest.fixture
def page(_session_page):
    """The session's page, its error lists emptied for this test."""
    _session_page.errors.clear()
    yield _session_page
    try:
        _session_page.settle(timeout=30_000)
    except Exception:  # a failed test may leave the page anywhere; the next goto recovers
        pass


@pytest.fixture(scope="session")
def artifacts() -> Path:
    ARTIFACTS.mkdir(exist_ok=True)
    return ARTIFACTS


@pytest.fixture
def sized(_session_page):
    """``sized(width, height)`` resizes the session page's window for this test (a projector, a
    phone); the next test gets the usual 1300×900 back."""
    page = _session_page.page

    def size(width: int, height: int) -> None:
        page.set_viewport_size({"width": width, "height": height})

    yield size
    page.set_viewport_size({"width": 1300, "height": 900})
