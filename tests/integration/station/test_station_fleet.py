"""The station with a large fleet, in real headless Chromium: 300 swarm robots on the local
stack (real mosquitto, the shadow service), `vahr station` against it, one page.

The map draws them on a canvas, clustered where they crowd, and a click on a robot still
selects it; the robots panel is a virtualized list with a search box that finds robots by
spoken or thing name, narrows them by status and zone, says when nothing matches, and
selects the robot clicked in the results.

One stack, swarm, station and browser serve the module; each test opens its own page. The
first test writes docs/images/station-fleet.png.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from typing import TYPE_CHECKING, Any

import msgspec
import pytest
from playwright.sync_api import sync_playwright

from tests.support.browser import Watch, launch
from tests.support.swarm_runner import SwarmThread, swarm_fleet
from tests.support.vahr_up import ROOT
from vahr.plumbing.lifetime import spawn
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.plumbing.ports import free_port
from vahr.protocol import encode, new_command, topics
from vahr.twin.stack import LocalStack, StackConfig

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from playwright.sync_api import Browser, Page, ViewportSize

pytestmark = pytest.mark.slow

ROBOTS = 300
IMAGES = ROOT / "docs" / "images"
VIEWPORT: ViewportSize = {"width": 1280, "height": 800}
WAIT_S = 60.0


class Fleet(msgspec.Struct):
    """The running pieces the tests talk to."""

    station: str
    mqtt_port: int


@pytest.fixture(scope="module")
def running(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Fleet]:
    state = tmp_path_factory.mktemp("station-fleet")
    mqtt_port = free_port()
    config = StackConfig(
        state_dir=state / "stack",
        mqtts_port=free_port(),
        mqtt_port=mqtt_port,
        api_port=free_port(),
    )
    fleet_file = state / "fleet.yaml"
    fleet_file.write_bytes(msgspec.yaml.encode(swarm_fleet(ROBOTS)))
    broker = f"mqtt://127.0.0.1:{mqtt_port}"
    with (
        LocalStack(config),
        SwarmThread(broker=broker, count=ROBOTS, speed_factor=5.0, listen_to_peers=False),
    ):
        station = spawn(
            [sys.executable, "-m", "vahr.cli", "station", "--broker", broker,
             "--api", f"http://127.0.0.1:{config.api_port}", "--fleet", str(fleet_file),
             "--port", str(free_port()), "--no-voice", "--json"],
            started_for=state, stdout=subprocess.PIPE, text=True, cwd=ROOT,
        )  # fmt: skip
        try:
            assert station.stdout is not None
            url = json.loads(station.stdout.readline())["station"]
            yield Fleet(station=url, mqtt_port=mqtt_port)
        finally:
            station.send_signal(signal.SIGTERM)
            station.wait(30)


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    with sync_playwright() as playwright:
        launched = launch(playwright)
        try:
            yield launched
        finally:
            launched.close()


@pytest.fixture
def page(browser: Browser, running: Fleet) -> Iterator[Page]:
    """The station's page with every robot listed; no errors allowed on it."""
    context = browser.new_context(viewport=VIEWPORT)
    opened = context.new_page()
    watch = Watch(opened)
    opened.goto(running.station + "?metrics=1")
    opened.locator('#link-state[data-state="live"]').wait_for(timeout=WAIT_S * 1000)
    opened.locator('.robot-row[data-status="idle"]').first.wait_for(timeout=WAIT_S * 1000)
    try:
        yield opened
    finally:
        context.close()
    assert watch.problems == [], "the page logged errors or had failed requests"


def eventually(check: Callable[[], Any], what: str, timeout_s: float = WAIT_S) -> Any:
    deadline = time.monotonic() + timeout_s
    while not (result := check()):
        if time.monotonic() > deadline:
            pytest.fail(f"not within {timeout_s:g} s: {what}")
        time.sleep(0.2)
    return result


def send_fleet(running: Fleet, zone: str) -> None:
    with MqttClient(MqttEndpoint(host="127.0.0.1", port=running.mqtt_port)) as link:
        link.publish(
            topics.FLEET_CMD, encode(new_command("navigate", {"zone": zone}, source="console"))
        )


def selected(page: Page) -> str | None:
    thing: str | None = page.evaluate("() => window.vahrStation.store.selected")
    return thing


# -- the map ------------------------------------------------------------------------------


def test_the_map_draws_the_fleet_on_a_canvas_in_clusters_and_a_click_selects_a_robot(
    page: Page, running: Fleet
) -> None:
    # Then no robot is an SVG element: one canvas holds them, crowds drawn as one mark
    assert page.locator("#map g.robot").count() == 0
    assert page.locator("canvas.robot-layer").count() == 1
    marks = page.evaluate(
        "() => window.vahrStation.map.layer.marks.map((m) => ({x: m.x, y: m.y, things: m.things}))"
    )
    assert sorted(t for m in marks for t in m["things"]) == [
        f"swarm{i:04d}" for i in range(1, ROBOTS + 1)
    ]
    assert len(marks) < ROBOTS
    # When every robot is sent to zone A, they are drawn driving there
    send_fleet(running, "A")
    eventually(
        lambda: (
            page.evaluate(
                "() => window.vahrMetrics.shown.filter((s) => s.status === 'navigating').length"
            )
            >= ROBOTS
        ),
        "every robot shown driving",
    )
    time.sleep(1.0)
    IMAGES.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(IMAGES / "station-fleet.png"), animations="disabled")
    # And a click on a robot drawn alone selects that robot, in the panel too
    page.evaluate("() => window.vahrStation.map.select(null)")
    box = page.locator("canvas.robot-layer").bounding_box()
    assert box is not None

    def click_a_robot_drawn_alone() -> str | None:
        # Where it is drawn now: the robots are driving, and on a busy machine one read a
        # while ago may be out of the pointer's reach by the time of the click.
        marks = page.evaluate("() => window.vahrStation.map.layer.marks")
        single = next((m for m in marks if len(m["things"]) == 1), None)
        if single is None:
            return None
        page.mouse.click(box["x"] + single["x"], box["y"] + single["y"])
        return selected(page)

    chosen = eventually(click_a_robot_drawn_alone, "a robot drawn alone, selected by a click")
    assert chosen.startswith("swarm")
    page.locator(f'.robot-row.selected[data-thing="{chosen}"]').wait_for(timeout=10_000)


# -- the robots panel and its search -------------------------------------------------------


def test_the_robots_panel_has_elements_only_for_the_rows_in_view(page: Page) -> None:
    rows = page.locator("#robots .robot-row")
    assert 5 <= rows.count() <= 40
    assert page.locator("#robots-count").inner_text() == f"{ROBOTS} robots"
    # Scrolled to the end, the last robot is there
    page.locator("#robots").evaluate("(list) => { list.scrollTop = list.scrollHeight; }")
    page.locator(f'.robot-row[data-thing="swarm{ROBOTS:04d}"]').wait_for(timeout=10_000)


def test_the_search_finds_a_robot_by_spoken_name_and_a_click_selects_it(page: Page) -> None:
    search = page.locator('input[type="search"]')
    search.fill("swarm 17")
    # Then the robot of that name comes first, then those whose names start with it
    first = page.locator("#robots .robot-row:not([hidden])").first
    eventually(lambda: first.get_attribute("data-thing") == "swarm0017", "swarm 17 listed first")
    assert page.locator("#robots-count").inner_text() == f"11 of {ROBOTS} robots"
    # And a click on it selects it, as a click on the map would
    first.locator("button").click()
    assert selected(page) == "swarm0017"
    assert "swarm 17 selected" in page.locator("#map-hint").inner_text()


def test_the_search_finds_by_thing_name_and_filters_by_status_and_zone(page: Page) -> None:
    page.locator('input[type="search"]').fill("swarm0250")
    row = page.locator("#robots .robot-row:not([hidden])").first
    eventually(lambda: row.get_attribute("data-thing") == "swarm0250", "swarm0250 found")
    # A status no robot has and a zone no robot is in: nothing, and the page says so
    page.locator('input[type="search"]').fill("")
    page.locator("#robot-status-filter").select_option("stuck")
    page.locator("#robots-none").wait_for(state="visible", timeout=10_000)
    assert page.locator("#robots-none").inner_text() == "No robot matches."
    assert page.locator("#robots-count").inner_text() == f"0 of {ROBOTS} robots"
    # Any status again: every robot is listed once more
    page.locator("#robot-status-filter").select_option("")
    page.locator("#robots-none").wait_for(state="hidden", timeout=10_000)
    assert page.locator("#robots-count").inner_text() == f"{ROBOTS} robots"


def test_a_search_that_matches_nothing_says_so(page: Page) -> None:
    page.locator('input[type="search"]').fill("forklift 9")
    page.locator("#robots-none").wait_for(state="visible", timeout=10_000)
    assert page.locator("#robots .robot-row:not([hidden])").count() == 0
