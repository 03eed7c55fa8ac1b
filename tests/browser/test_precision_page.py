"""The work–precision panel (static/js/precision.js) in a real page: mounted into a scene page,
Run clicked, the fitted orders read from its table and checked against the textbook orders.

The server here is the app with the precision router included if app/main.py does not include it
yet (``precision_app``, a uvicorn factory), so the test does not depend on the wiring's timing.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[2]


def precision_app():
    """app.main's app, with /api/v1/precision whether or not it is wired there yet."""
    from app.main import app
    from app.routes import precision

    if not any(getattr(r, "path", "") == "/api/v1/precision" for r in app.routes):
        app.include_router(precision.router)
    return app


@pytest.fixture(scope="module")
def precision_server(tmp_path_factory):
    from servers import free_port, serving

    port = free_port()
    env = {**os.environ, "LAGRANGE_LAB_CACHE": str(tmp_path_factory.mktemp("cache"))}
    command = [
        sys.executable,
        "-m",
        "uvicorn",
        "test_precision_page:precision_app",
        "--factory",
        "--app-dir",
        str(Path(__file__).parent),
        "--port",
        str(port),
        "--log-level",
        "warning",
    ]
    with serving(command, port, env=env, cwd=ROOT) as (url, _):
        yield url


@pytest.fixture(scope="module")
def panel_page(browser, precision_server):
    ctx = browser.new_context(viewport={"width": 1300, "height": 900}, bypass_csp=True)
    page = ctx.new_page()
    errors: list[str] = []
    page.on("console", lambda m: m.type == "error" and errors.append(m.text))
    page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
    page.goto(f"{precision_server}/scenes/simple_pendulum")
    page.evaluate(
        """async () => {
          const m = await import('/static/js/precision.js');
          const box = document.createElement('div');
          box.id = 'precision-test';
          document.querySelector('main').append(box);
          window.__precision = m.mountPrecision(box, {
            sceneId: 'simple_pendulum',
            getState: () => ({ initial: { theta: 1.0, theta_dot: 0 } }),
          });
        }"""
    )
    page.wait_for_selector("#precision .methods[data-ready='1']")
    yield page, errors
    ctx.close()


def test_run_shows_fitted_orders_near_the_textbook_orders(panel_page):
    page, errors = panel_page
    checked = page.eval_on_selector_all(
        "#precision .methods input:checked", "boxes => boxes.map(b => b.value)"
    )
    assert checked == ["euler", "rk4", "DOP853"]
    # RK4 in its asymptotic range on this swing, DOP853 over 1e-5 … 1e-10
    # (tests/simulation/test_precision.py)
    page.fill("#precision-step-from", "0.0125")
    page.fill("#precision-step-to", "0.0015625")
    page.fill("#precision-tol-from", "1e-5")
    page.fill("#precision-tol-to", "1e-10")
    page.fill("#precision-count", "6")
    page.fill("#precision-t-end", "10")
    page.check("#precision-long-run")
    page.click("#precision-run")
    page.wait_for_selector("#precision[data-state='done']", timeout=90_000)
    rows = page.eval_on_selector_all(
        "#precision-orders tr[data-method]",
        "rows => rows.map(r => [r.dataset.method, r.cells[1].textContent, "
        "r.querySelector('.fitted').textContent])",
    )
    found = {m: (int(order), fitted) for m, order, fitted in rows}
    assert set(found) == {"euler", "rk4", "DOP853"}
    assert found["rk4"][0] == 4 and abs(float(found["rk4"][1]) - 4) <= 0.3
    assert found["DOP853"][0] == 8 and abs(float(found["DOP853"][1]) - 8) <= 0.3
    # the three log–log plots and the long run's are drawn
    for plot in ("time", "evals", "energy", "long"):
        assert page.locator(f"#precision-plot-{plot} .main-svg").count() >= 1, plot
    long_text = page.inner_text("#precision-long")
    # as many periods as the 4.5 s budget allows (100 to 1000): the page says how many
    assert re.search(r"\b\d{3,4} periods", long_text) and "symplectic Euler" in long_text
    assert "Done in" in page.inner_text("#precision-status")
    assert not errors, errors


def test_axe_finds_nothing_serious_in_the_panel(panel_page):
    from axe_playwright_python.sync_playwright import Axe

    page, _ = panel_page
    found = Axe().run(page, context="#precision").response["violations"]
    serious = [f"{v['id']}: {v['help']}" for v in found if v["impact"] in ("serious", "critical")]
    assert serious == []


def test_a_refused_request_is_shown_in_words(panel_page):
    page, errors = panel_page
    page.fill("#precision-step-from", "1e-7")  # t_end / step past 200000 steps
    page.fill("#precision-step-to", "1e-8")
    page.click("#precision-run")
    page.wait_for_selector("#precision[data-state='error']", timeout=30_000)
    assert "steps[0]" in page.inner_text("#precision-status")
    errors.clear()  # the browser logs the 422 itself: that is the point of this test


def test_a_posted_spec_runs_from_the_panel(browser, precision_server):
    ctx = browser.new_context(viewport={"width": 1024, "height": 768}, bypass_csp=True)
    page = ctx.new_page()
    try:
        page.goto(f"{precision_server}/editor")
        page.evaluate(
            """async () => {
              const m = await import('/static/js/precision.js');
              const spec = (await (await fetch('/api/v1/scenes/simple_pendulum')).json()).spec;
              const box = document.createElement('div');
              document.querySelector('main').append(box);
              m.mountPrecision(box, { spec, getState: () => ({ initial: { theta: 1.0 } }) });
            }"""
        )
        page.wait_for_selector("#precision .methods[data-ready='1']")
        page.uncheck("#precision .methods input[value='euler']")
        page.uncheck("#precision .methods input[value='DOP853']")
        page.fill("#precision-step-from", "0.0125")
        page.fill("#precision-step-to", "0.003125")
        page.fill("#precision-count", "3")
        page.click("#precision-run")
        page.wait_for_selector("#precision[data-state='done']", timeout=90_000)
        fitted = page.inner_text("#precision-orders tr[data-method='rk4'] .fitted")
        assert abs(float(fitted) - 4) <= 0.3
    finally:
        ctx.close()
