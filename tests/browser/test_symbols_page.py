"""Names shown as symbols where nothing typesets them (student play-test: 'theta_dot' in a code
font beside sliders, 'dL/dtheta_dot' under equations, 'q = (theta1, theta2)' on the cards): the
symbol on the page, the name the editor and answers use on hover."""

from __future__ import annotations

import pytest

from app.routes.pages import symbol

pytestmark = pytest.mark.browser


def test_the_catalog_card_lists_coordinates_as_symbols(server, page):
    p = page.page
    p.goto(f"{server}/")
    card = p.locator(".card", has_text="Double pendulum")
    assert card.locator(".coords").inner_text() == "q = (θ₁, θ₂)"
    cart = p.locator(".card", has_text="Pendulum on a cart").locator(".coords").inner_text()
    assert cart == "q = (x, θ)"


def test_sliders_and_line_captions_show_symbols_with_their_names_on_hover(server, page):
    p = page.page
    p.goto(f"{server}/scenes/double_pendulum")
    p.wait_for_selector("#steps[data-typeset='1']", state="attached", timeout=90_000)
    row = p.locator("#initial .control", has=p.locator("#n-theta1_dot"))
    assert row.locator(".name").inner_text() == "θ̇₁"
    assert row.locator("label").get_attribute("title") == "theta1_dot"
    line = p.locator("#steps .math-line[data-label='dL/dtheta1_dot']")
    # text_content: a step out of sight is not rendered (content-visibility), so no innerText
    assert line.locator(".line-label").text_content() == "∂L/∂θ̇₁"
    assert line.locator(".line-label").get_attribute("title") == "dL/dtheta1_dot"
    eom = p.locator("#steps .math-line[data-label='EoM theta2'] .line-label")
    assert eom.text_content() == "EoM θ₂"
    options = p.eval_on_selector_all("#phase-q option", "os => os.map((o) => [o.value, o.text])")
    assert options == [["theta1", "θ₁"], ["theta2", "θ₂"]]


@pytest.mark.parametrize(
    ("name", "shown"),
    [("theta1", "θ₁"), ("Omega", "Ω"), ("x", "x"), ("m2", "m₂"), ("x_cart", "x_cart")],
)
def test_the_server_writes_the_same_symbols(name, shown):
    assert symbol(name) == shown
