"""The fleet's task queue and "any robot" on the station, in real headless Chromium.

The station runs in-process on a real mosquitto, its task queue read from a dispatcher's
`GET /vahr/tasks` (here a small HTTP server on loopback serving what the test sets, as the
dispatcher would), and its assistant records what it is asked. The page shows the queue and
who took which task as the dispatcher's answer changes, hides the card when there is no
dispatcher, and the keyboard-and-mouse panel's "Any robot" then a zone asks the assistant
to send a robot there. The first test writes docs/images/station-tasks.png.
"""

from __future__ import annotations

import json
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import TYPE_CHECKING, Any

import pytest
from playwright.sync_api import sync_playwright

from tests.support.browser import Watch, launch
from tests.support.station_stand_ins import RecordingAssistant
from tests.support.vahr_up import ROOT
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.plumbing.ports import LOOPBACK, free_port
from vahr.station.assembly import Station, StationConfig

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from playwright.sync_api import Browser, Page, ViewportSize

    from vahr.domain import Fleet
    from vahr.twin.broker import Mosquitto

pytestmark = pytest.mark.slow

IMAGES = ROOT / "docs" / "images"
VIEWPORT: ViewportSize = {"width": 1280, "height": 800}
WAIT_MS = 15_000


class Dispatcher:
    """Serves `{"tasks": [...]}` at /vahr/tasks (404 while `tasks` is None)."""

    def __init__(self) -> None:
        self.tasks: list[dict[str, Any]] | None = []
        served = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:  # noqa: N802
                if self.path != "/vahr/tasks" or served.tasks is None:
                    self.send_error(404)
                    return
                body = json.dumps({"tasks": served.tasks}).encode()
                self.send_response(200)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def log_message(self, *args: object) -> None:
                pass

        self.server = ThreadingHTTPServer((LOOPBACK, 0), Handler)
        self.url = f"http://{LOOPBACK}:{self.server.server_address[1]}/vahr/tasks"
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)


def task(id: str, status: str, thing: str | None = None, zone: str = "C") -> dict[str, Any]:
    """A task as `GET /vahr/tasks` serves it (`vahr.dispatch.Task`)."""
    return {
        "id": id, "request": f"order-{id}", "kind": "deliver", "zone": zone,
        "pickup": "LOADING", "group": None, "robots": [], "status": status, "thing": thing,
        "created_at": f"2026-11-26T23:00:0{id[-1]}.000000Z", "assigned_at": None,
        "outcome": None, "version": 1,
    }  # fmt: skip


@pytest.fixture
def dispatcher() -> Iterator[Dispatcher]:
    running = Dispatcher()
    running.thread.start()
    try:
        yield running
    finally:
        running.server.shutdown()
        running.server.server_close()


@pytest.fixture
def station(
    mosquitto: Mosquitto, dispatcher: Dispatcher, fleet: Fleet
) -> Iterator[tuple[Station, RecordingAssistant]]:
    assistant = RecordingAssistant()
    link = MqttClient(MqttEndpoint(host=LOOPBACK, port=mosquitto.config.plain_port or 0))
    link.connect()
    config = StationConfig(port=free_port(), voice=False, tasks_url=dispatcher.url)
    running = Station(config, fleet, link=link, assistant=assistant)  # type: ignore[arg-type]
    try:
        with running:
            yield running, assistant
    finally:
        link.stop()


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    # One browser for the file (starting one costs some 2 s of CPU); a page of its own,
    # in a context of its own, for each test.
    with sync_playwright() as playwright:
        launched = launch(playwright)
        try:
            yield launched
        finally:
            launched.close()


@pytest.fixture
def page(browser: Browser, station: tuple[Station, RecordingAssistant]) -> Iterator[Page]:
    context = browser.new_context(viewport=VIEWPORT)
    try:
        opened = context.new_page()
        watch = Watch(opened)
        opened.goto(station[0].url)
        opened.locator('#link-state[data-state="live"]').wait_for(timeout=WAIT_MS)
        yield opened
        assert watch.problems == [], "the page logged errors or had failed requests"
    finally:
        context.close()


def eventually(check: Callable[[], Any], what: str, timeout_s: float = 15.0) -> Any:
    deadline = time.monotonic() + timeout_s
    while not (result := check()):
        if time.monotonic() > deadline:
            pytest.fail(f"not within {timeout_s:g} s: {what}")
        time.sleep(0.1)
    return result


def lines(page: Page) -> list[str]:
    texts: list[str] = page.locator("#task-list li").all_inner_texts()
    return [" ".join(text.split()) for text in texts]


def test_the_queue_and_who_took_which_task_follow_the_dispatcher(
    page: Page, dispatcher: Dispatcher
) -> None:
    # An empty queue: the card is shown, saying so
    page.locator("#tasks").wait_for(state="visible", timeout=WAIT_MS)
    eventually(lambda: lines(page) == ["Nothing queued: every task has a robot."], "empty queue")
    # When two deliveries wait for a robot
    dispatcher.tasks = [task("t1", "queued"), task("t2", "queued", zone="B")]
    eventually(
        lambda: lines(page) == ["queued deliver to zone C first in line",
                                "queued deliver to zone B 2nd in line"],
        "two tasks in line",
    )  # fmt: skip
    assert page.locator("#task-count").inner_text() == "2 queued · 0 under way"
    IMAGES.mkdir(parents=True, exist_ok=True)
    page.locator("#tasks").screenshot(path=str(IMAGES / "station-tasks.png"), animations="disabled")
    # When placebot one takes the first, and the second is cancelled
    dispatcher.tasks = [task("t1", "assigned", "placebot1"), task("t2", "cancelled", zone="B")]
    eventually(
        lambda: lines(page) == ["under way deliver to zone C placebot one",
                                "cancelled deliver to zone B cancelled"],
        "placebot one took the delivery to C",
    )  # fmt: skip
    # And once it is done, it says who did it
    dispatcher.tasks = [task("t1", "done", "placebot1"), task("t2", "cancelled", zone="B")]
    eventually(lambda: "done by placebot one" in lines(page)[-1], "done by placebot one")


def test_without_a_dispatcher_the_queue_is_not_shown(page: Page, dispatcher: Dispatcher) -> None:
    page.locator("#tasks").wait_for(state="visible", timeout=WAIT_MS)
    dispatcher.tasks = None  # the deployment answers 404 at /vahr/tasks
    page.locator("#tasks").wait_for(state="hidden", timeout=WAIT_MS)


def test_any_robot_then_a_zone_asks_the_assistant_to_send_a_robot_there(
    page: Page, station: tuple[Station, RecordingAssistant]
) -> None:
    assistant = station[1]
    zone_c = page.locator('#zone-buttons button[data-zone="C"]')
    assert zone_c.is_disabled()
    # When the operator picks "Any robot" (the 0 key), then zone C by a click
    page.locator("#map-title").click()
    page.keyboard.press("0")
    assert page.locator("button[data-any]").get_attribute("aria-pressed") == "true"
    zone_c.click()
    # Then the assistant is asked as a person would ask it, and its answer is shown
    eventually(lambda: assistant.asked, "the assistant asked")
    assert assistant.asked == [("send a robot to zone C", "station")]
    eventually(lambda: "It is sunny." in page.locator("#panel-status").inner_text(), "reply shown")
    # And selecting a robot leaves "any robot"
    page.keyboard.press("1")
    assert page.locator("button[data-any]").get_attribute("aria-pressed") == "false"
