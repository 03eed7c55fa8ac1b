"""The assignment pages in a real browser (Debian's Chromium, Playwright): a student answers a
part and sees the checker's code, feedback and score; the instructor previews the keys and draws
the class report; both pages hold at lecture size and on a phone, and axe finds nothing serious."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import httpx
import pytest
from servers import free_port, serving

from app.assignments import tokens
from app.assignments.db import engine_for, forget_engines
from app.assignments.store import Store

pytestmark = pytest.mark.browser
CHROMIUM = "/usr/bin/chromium"
ROOT = Path(__file__).resolve().parents[2]
SERIOUS = {"serious", "critical"}

if not Path(CHROMIUM).exists():
    pytest.skip(
        "Debian's chromium is not installed (apt-get install chromium)", allow_module_level=True
    )


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """A server with its own SQLite database, an instructor, a student and a deployed week1."""
    folder = tmp_path_factory.mktemp("assignment-pages")
    url = f"sqlite:///{folder / 'assignments.sqlite3'}"
    store = Store(engine_for(url))
    teacher = tokens.create(store, "instructor", "ada")
    pupils = {w: tokens.create(store, "student", f"s{w}") for w in (1300, 1024, 390)}
    pupil = pupils[1300]
    port = free_port()
    env = {**os.environ, "LAGRANGE_LAB_DATABASE_URL": url, "LAGRANGE_LAB_POOL_WORKERS": "2"}
    command = [
        sys.executable,
        "-m",
        "uvicorn",
        "app.main:app",
        "--port",
        str(port),
        "--log-level",
        "warning",
    ]
    with serving(command, port, env=env, cwd=ROOT) as (base, _):
        r = httpx.post(
            f"{base}/api/v1/assignments/templates/pendulum_energies/deploy",
            json={"assignment_id": "week1", "count": 2},
            headers={"Authorization": f"Bearer {teacher}"},
            timeout=300,
        )
        assert r.status_code == 201, r.text
        yield {
            "base": base,
            "teacher": teacher,
            "pupil": pupil,
            "pupils": pupils,
            "preview": r.json(),
        }
    forget_engines()


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(
            executable_path=CHROMIUM, headless=True, args=["--no-sandbox", "--disable-gpu"]
        )
        yield b
        b.close()


def new_page(browser, width=1300, height=900):
    ctx = browser.new_context(viewport={"width": width, "height": height}, bypass_csp=True)
    page = ctx.new_page()
    errors = []
    page.on("console", lambda m: m.type == "error" and errors.append(m.text))
    page.on("pageerror", lambda e: errors.append(str(e)))
    return ctx, page, errors


def serious(page) -> list[str]:
    from axe_playwright_python.sync_playwright import Axe

    found = Axe().run(page).response["violations"]
    return [f"{v['id']}: {v['help']}" for v in found if v["impact"] in SERIOUS]


def no_sideways_scroll(page) -> bool:
    return page.evaluate("document.documentElement.scrollWidth <= window.innerWidth + 1")


@pytest.mark.parametrize(("width", "height"), [(1300, 900), (1024, 768), (390, 844)])
def test_a_student_answers_a_part_and_sees_code_feedback_and_score(site, browser, width, height):
    ctx, page, errors = new_page(browser, width, height)
    try:
        pupil = site["pupils"][width]  # a student of their own: no earlier answer on the page
        page.goto(f"{site['base']}/assignments/week1#token={pupil}")
        page.wait_for_selector("#answer-T")
        assert "token=" not in page.url  # the fragment is taken out of the address bar
        mine = httpx.get(
            f"{site['base']}/api/v1/assignments/week1/mine",
            headers={"Authorization": f"Bearer {site['pupil']}"},
        ).json()
        m = mine["parameters"]["m"]
        page.fill("#answer-T", f"2*{m}*l^2*theta_dot^2")  # four times T: a factor
        page.click("#part-T button")
        page.wait_for_function("document.querySelector('#part-T .feedback li')")
        first = page.text_content("#part-T .feedback li")
        assert first.startswith("T.wrong_factor"), first
        page.wait_for_function("document.querySelector('#score-T').textContent.includes(' used')")
        page.wait_for_selector("#steps li.step")
        shown = page.eval_on_selector_all("#steps li.step", "els => els.map(e => e.dataset.step)")
        assert "energy" not in shown and "lagrange" not in shown  # graded: T, V, L, eom open
        assert no_sideways_scroll(page)
        assert serious(page) == []
        assert errors == []
    finally:
        ctx.close()


def test_the_student_page_shows_no_key(site, browser):
    ctx, page, _ = new_page(browser)
    try:
        page.goto(f"{site['base']}/assignments/week1#token={site['pupil']}")
        page.wait_for_selector("#answer-T")
        html = page.content()
        for v in site["preview"]["variants"]:
            for k in v["keys"]:
                assert k["latex"] not in html and k["plain"] not in html
    finally:
        ctx.close()


@pytest.mark.parametrize(("width", "height"), [(1300, 900), (390, 844)])
def test_the_instructor_previews_keys_and_draws_the_report(site, browser, width, height):
    ctx, page, errors = new_page(browser, width, height)
    try:
        page.goto(f"{site['base']}/assignments#token={site['teacher']}")
        page.wait_for_selector("#template option", state="attached")
        page.fill("#open-id", "week1")
        page.click("#open-form button[type=submit]")
        page.wait_for_selector(".assignment-preview td")
        assert page.locator(".assignment-preview tr").count() == 3  # header + 2 variants
        page.click("#report-button")
        page.wait_for_selector("#hist-T .main-svg", timeout=60_000)
        page.wait_for_selector("#csv", state="visible")
        assert no_sideways_scroll(page)
        assert serious(page) == []
        assert errors == []
    finally:
        ctx.close()
