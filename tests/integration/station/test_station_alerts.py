"""The station's alerts in real headless Chromium, against `vahr up` on free ports: a fault
injected into a simulated robot (`vahr fault`) is announced by the assistant and shown on
the page as an alert naming the robot, with the robot ringed on the map and a beep; a key or
a click acknowledges it, on every page, and during a session the acknowledgment is logged
as an interaction.

One `vahr up` and one browser serve the module; each test opens its own pages. The first
test writes docs/images/station-alert.png.
"""

from __future__ import annotations

import json
import subprocess
import time
import urllib.request
from typing import TYPE_CHECKING, Any

import pytest
from playwright.sync_api import sync_playwright

from tests.support.browser import Watch, launch
from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, say, start_up, stop_up
from vahr.experiment.eventlog import Kind, read_log
from vahr.plumbing.lifetime import spawn
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from playwright.sync_api import Browser, BrowserContext, Page

pytestmark = pytest.mark.slow

IMAGES = ROOT / "docs" / "images"
VIEWPORT = {"width": 1280, "height": 800}
WAIT_S = 30.0


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    running = start_up(
        tmp_path_factory.mktemp("station-alerts-up"),
        "--station-port", str(free_port()),
        "--sim-speed-factor", "10",
        # `vahr station` is started on its plaintext listener too.
        plaintext=True,
    )  # fmt: skip
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
def pages(browser: Browser, up: Up) -> Iterator[Callable[[], Page]]:
    """Open station pages, connected and showing the robots; no errors allowed on any."""
    opened: list[tuple[BrowserContext, Watch]] = []

    def open_page() -> Page:
        context = browser.new_context(viewport=VIEWPORT)
        page = context.new_page()
        opened.append((context, Watch(page)))
        page.goto(up.endpoints["station"] + "?metrics=1")
        page.locator('#link-state[data-state="live"]').wait_for(timeout=WAIT_S * 1000)
        page.locator('.robot-row[data-status="idle"]').first.wait_for(timeout=WAIT_S * 1000)
        # A page plays sound once it was clicked: the operator has been using it.
        page.locator("#robots-title").click()
        return page

    try:
        yield open_page
    finally:
        for context, _ in opened:
            context.close()
    assert [w.problems for _, w in opened] == [[]] * len(opened), "a page logged errors"


def fault(up: Up, thing: str, kind: str, *extra: str) -> None:
    """`vahr fault THING KIND` against the running system."""
    done = subprocess.run(
        [*VAHR, "fault", thing, kind, *extra, "--api", up.endpoints["api"]],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr


def open_alerts(up: Up) -> list[dict[str, Any]]:
    with urllib.request.urlopen(up.endpoints["station"] + "api/snapshot", timeout=10) as answer:
        alerts: list[dict[str, Any]] = json.loads(answer.read())["alerts"]
        return alerts


def eventually(check: Callable[[], Any], what: str, timeout_s: float = WAIT_S) -> Any:
    deadline = time.monotonic() + timeout_s
    while not (result := check()):
        if time.monotonic() > deadline:
            pytest.fail(f"not within {timeout_s:g} s: {what}")
        time.sleep(0.1)
    return result


def ringed(page: Page, thing: str) -> bool:
    classes = page.locator(f'#map .robot[data-thing="{thing}"]').get_attribute("class") or ""
    return "alerting" in classes.split()


def test_a_stuck_robot_raises_an_alert_that_a_key_acknowledges_on_every_page(
    up: Up, pages: Callable[[], Page]
) -> None:
    operator, observer = pages(), pages()
    # Given placebot one told to get stuck, then sent to zone B
    fault(up, "placebot1", "stuck")
    turn = say(up.endpoints["api"], "send placebot one to zone b")
    assert turn["commands"], turn
    # Then the page shows an alert naming the robot and what happened
    alert = operator.get_by_role("alert").filter(has_text="placebot one")
    alert.wait_for(timeout=WAIT_S * 1000)
    assert "stuck" in alert.inner_text().lower()
    assert "Placebot one is stuck on its way to zone B" in alert.inner_text()
    # And the robot is ringed on the map, marked in the list, and the page beeped
    assert ringed(operator, "placebot1") and not ringed(operator, "placebot2")
    row = operator.locator('.robot-row[data-thing="placebot1"]')
    assert "alerting" in (row.get_attribute("class") or "")
    assert operator.evaluate("() => window.vahrMetrics.beeps") == 1
    # And the conversation shows what the assistant said
    said = operator.locator("#conversation .entry.announcement")
    assert "Placebot one is stuck" in said.last.inner_text()
    assert "unprompted" in said.last.inner_text()
    observer.get_by_role("alert").wait_for(timeout=WAIT_S * 1000)
    time.sleep(1.2)  # the ring's pulse settles before the picture
    operator.locator(".map-card").screenshot(
        path=str(IMAGES / "station-alert.png"), animations="disabled"
    )
    # When the operator presses Enter (the focus on no control)
    operator.keyboard.press("Enter")
    # Then the alert goes, on this page and on the observer's, and the ring with it
    for page in (operator, observer):
        page.get_by_role("alert").wait_for(state="detached", timeout=WAIT_S * 1000)
        eventually(lambda page=page: not ringed(page, "placebot1"), "the ring gone")
    assert open_alerts(up) == []
    # And a page opened now does not raise it again
    assert pages().get_by_role("alert").count() == 0
    fault(up, "placebot1", "clear")


def test_an_alert_acknowledged_with_a_click_is_logged_as_an_interaction_in_a_session(
    up: Up, pages: Callable[[], Page], tmp_path: Path
) -> None:
    page = pages()
    # Given a keyboard-and-mouse session of the experiment running against the system
    experiment = spawn(
        [*VAHR, "experiment", "--participant", "P08", "--method", "keyboard", "--trial", "1",
         "--log-dir", str(tmp_path), "--broker", up.endpoints["mqtt"],
         "--api", up.endpoints["api"], "--task-timeout", "120"],
        started_for=tmp_path, cwd=ROOT, env=clean_env(), stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        page.locator("#verdicts li.running").wait_for(timeout=WAIT_S * 1000)
        # When placebot two goes offline, and the participant clicks the alert's button
        fault(up, "placebot2", "offline", "--offline-s", "3")
        alert = page.get_by_role("alert").filter(has_text="placebot two")
        alert.wait_for(timeout=WAIT_S * 1000)
        assert "offline" in alert.inner_text().lower()
        assert ringed(page, "placebot2")
        alert.get_by_role("button", name="Acknowledge").click()
        # Then the alert goes
        alert.wait_for(state="detached", timeout=WAIT_S * 1000)
        eventually(lambda: open_alerts(up) == [], "the station's alert acknowledged")
        time.sleep(0.5)  # the click's end reaches the session's log
    finally:
        assert experiment.stdin is not None
        experiment.stdin.close()
        experiment.wait(timeout=60)
    assert experiment.returncode == 0, experiment.stderr.read() if experiment.stderr else ""
    # And the session's log holds the click as an interaction that sent no command
    (log_file,) = tmp_path.glob("P08-keyboard-trial1.sqlite")
    entries = read_log(log_file)
    ended = [
        e.data
        for e in entries
        if e.kind == Kind.INTERACTION_ENDED and e.data.get("source") == "station"
    ]
    acknowledged = [e for e in ended if e["text"] == "acknowledge alert placebot2 offline"]
    assert len(acknowledged) == 1, ended
    assert acknowledged[0]["channel"] == "click"
    assert acknowledged[0]["commands"] == [] and acknowledged[0].get("counts") is False
