"""The first minute with a fleet of one's own, as a new user lives it: `vahr up` on a small
hospital's fleet file, in German, with an empty model cache (every model learnt on the
spot). While it starts, `/vahr/health` says it is not ready; its endpoints line comes only
once every robot is online and the assistant answers; the first `vahr say` after it is
answered and the robot moves once; and the station, opened in an English browser, speaks
the stack's German, with the fleet's own keys and readable zone names."""

from __future__ import annotations

import threading
import time
import urllib.error
import urllib.request
from typing import TYPE_CHECKING

import pytest
from playwright.sync_api import sync_playwright

from tests.support.browser import Watch, launch
from tests.support.fleets import HOSPITAL
from tests.support.vahr_up import Up, say, start_up, stop_up
from vahr.plumbing.client import call
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from collections.abc import Iterator

# A first start on 2 busy cores learns the assistant's models for the fleet's names: the
# intent classifier, the slot-role taggers and the station's sentences and language model.
FIRST_START_S = 300.0


class HealthWatch:
    """`GET /vahr/health` asked every 0.2 s from before the stack starts."""

    def __init__(self, api: str) -> None:
        self.api = api
        self.seen: list[int | None] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.2):
            try:
                with urllib.request.urlopen(self.api + "/vahr/health", timeout=2) as answer:
                    self.seen.append(answer.status)
            except urllib.error.HTTPError as err:
                self.seen.append(err.code)
            except (urllib.error.URLError, OSError):
                self.seen.append(None)  # not serving yet

    def stop(self) -> list[int | None]:
        self._stop.set()
        self._thread.join(5)
        return self.seen


@pytest.fixture(scope="module")
def started(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Up, list[int | None]]]:
    api_port = free_port()
    watch = HealthWatch(f"http://127.0.0.1:{api_port}")
    cache = tmp_path_factory.mktemp("empty-cache")
    up = start_up(
        tmp_path_factory.mktemp("hospital"),
        "--fleet", str(HOSPITAL), "--locale", "de-DE", "--api-port", str(api_port),
        env={"XDG_CACHE_HOME": str(cache)}, timeout_s=FIRST_START_S,
    )  # fmt: skip
    seen = watch.stop()
    try:
        yield up, seen
    finally:
        stop_up(up.process)


def test_health_says_not_ready_until_the_endpoints_line(
    started: tuple[Up, list[int | None]],
) -> None:
    up, seen = started
    # While it started, health answered 503 (it did not claim a system that was not there)
    served = [status for status in seen if status is not None]
    assert 503 in served
    assert served.index(503) < (served.index(200) if 200 in served else len(served))
    # Once the endpoints line is out, it is ready, and every robot is online
    assert call(up.endpoints["api"], "GET", "/vahr/health")["ready"] is True
    online = call(up.endpoints["api"], "GET", "/vahr/status")["online"]
    assert online == {"hermes": True, "juno": True, "atlas": True, "iris": True}


def test_the_first_say_after_the_endpoints_is_answered_and_the_robot_moves_once(
    started: tuple[Up, list[int | None]],
) -> None:
    up, _ = started
    began = time.monotonic()
    turn = say(up.endpoints["api"], "schicke hermes in apotheke", "--locale", "de-DE")
    assert time.monotonic() - began < 30
    assert turn["speech"] == "Hermes ist unterwegs Richtung Apotheke."
    [command] = turn["commands"]
    assert up.wait_event(command, "accepted")["thing"] == "hermes"
    # Nothing else reaches hermes: the one command, carried out once
    time.sleep(2)
    accepted = []
    while not up.lines.empty():
        event = up.lines.get()
        if event.get("thing") == "hermes" and event.get("event") == "accepted":
            accepted.append(event["command_id"])
    assert accepted in ([], [command])  # the one above was read by wait_event


def test_the_station_speaks_the_stacks_german_with_the_fleets_keys(
    started: tuple[Up, list[int | None]],
) -> None:
    up, _ = started
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            # An English browser: the page follows the language people speak to the stack
            context = browser.new_context(viewport={"width": 1280, "height": 800}, locale="en-US")
            page = context.new_page()
            watch = Watch(page)
            page.goto(up.endpoints["station"])
            page.locator("#page-language").wait_for(timeout=30_000)
            assert page.locator("#page-language").input_value() == "de-DE"
            assert page.locator("#map-title").text_content() == "Grundriss"
            page.locator("#zone-buttons button").first.wait_for(timeout=30_000)
            # Keys from this fleet: four robots, and a free letter for every zone
            hint = page.locator("#panel-note").inner_text()
            assert "1–4" in hint.replace(" ", "") and "Zone" in hint
            keys = page.locator("#zone-buttons kbd").all_text_contents()
            assert keys == ["L", "P", "W", "R", "A"]
            # Zones by their German names, readable (at least 11 px high on the screen)
            names = page.locator("#map .zone-name").all_text_contents()
            assert names == ["Dock", "Apotheke", "Station Drei", "Empfang", "Labor"]
            heights = page.eval_on_selector_all(
                "#map .zone-name", "els => els.map(e => e.getBoundingClientRect().height)"
            )
            assert min(heights) >= 11
            # The list's words are German too
            page.locator(".robot-row").first.wait_for(timeout=30_000)
            assert "Zuletzt" in page.locator(".robot-row").first.inner_text()
            context.close()
            assert watch.problems == []
        finally:
            browser.close()
