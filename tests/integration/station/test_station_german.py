"""The station in German, in a browser: a German browser gets the page's words in German
with a language selector, the choice of English sticks across a reload, and against
`vahr up --locale de-DE` a request typed in German is answered in German."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest
from playwright.sync_api import sync_playwright

from tests.support.browser import Watch, launch
from tests.support.vahr_up import Up, start_up, stop_up

if TYPE_CHECKING:
    from collections.abc import Iterator

    from playwright.sync_api import Browser, Page, ViewportSize

VIEWPORT: ViewportSize = {"width": 1280, "height": 800}
WAIT_S = 30.0


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    running = start_up(tmp_path_factory.mktemp("german-station"), "--locale", "de-DE")
    try:
        yield running
    finally:
        stop_up(running.process)


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    with sync_playwright() as playwright:
        launched = launch(playwright)
        try:
            yield launched
        finally:
            launched.close()


@pytest.fixture
def german_page(browser: Browser, up: Up) -> Iterator[Page]:
    """The station's page in a browser whose language is German; no errors allowed on it."""
    context = browser.new_context(viewport=VIEWPORT, locale="de-DE")
    page = context.new_page()
    watch = Watch(page)
    page.goto(up.endpoints["station"])
    page.locator("#page-language").wait_for(timeout=WAIT_S * 1000)
    try:
        yield page
    finally:
        context.close()
    assert watch.problems == [], "the page logged errors or had failed requests"


def test_a_german_browser_gets_the_page_in_german(german_page: Page) -> None:
    assert german_page.locator("#map-title").text_content() == "Grundriss"
    assert german_page.locator("#robots-title").text_content() == "Roboter"
    assert german_page.locator("#robot-search").get_attribute("placeholder") == "Roboter finden"
    assert german_page.locator("html").get_attribute("lang") == "de"
    # Push-to-talk says in one line that it hears English only
    assert "nur auf Englisch" in (german_page.locator("#talk-state").text_content() or "")
    assert german_page.locator("#page-language").input_value() == "de-DE"


def test_english_chosen_in_the_selector_sticks_across_a_reload(german_page: Page) -> None:
    german_page.locator("#page-language").select_option("en-US")
    german_page.locator("#page-language").wait_for(timeout=WAIT_S * 1000)
    german_page.wait_for_function("document.querySelector('#map-title').textContent === 'Floor'")
    german_page.reload()
    german_page.locator("#page-language").wait_for(timeout=WAIT_S * 1000)
    assert german_page.locator("#map-title").text_content() == "Floor"
    assert german_page.locator("#page-language").input_value() == "en-US"


def test_a_request_typed_in_german_is_answered_in_german(german_page: Page) -> None:
    german_page.locator("#say-input").fill("schicke placebot zwo in zone c")
    german_page.locator("#say-form button[type=submit]").click()
    german_page.get_by_text("Placebot zwei ist unterwegs Richtung Zone C.").first.wait_for(
        timeout=WAIT_S * 1000
    )
