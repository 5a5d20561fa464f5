"""The operator station in real headless Chromium, against `vahr up` on free ports.

One `vahr up` and one browser serve the whole module; each test opens its own page (its own
browser context) and leaves the robots at rest, so the tests do not depend on each other.
The last test stops a robot's agent, which ends the shared `vahr up`.

The tests write the screenshots the docs show into docs/images/.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import time
import urllib.request
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest
from playwright.sync_api import sync_playwright

from tests.support.browser import Watch, launch
from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, say, start_up, stop_up
from vahr.experiment.eventlog import Kind, read_log
from vahr.plumbing.lifetime import spawn
from vahr.plumbing.ports import free_port
from vahr.speech.audio import Audio
from vahr.speech.tts import EspeakSynthesizer

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from playwright.sync_api import Browser, Page

pytestmark = pytest.mark.slow

IMAGES = ROOT / "docs" / "images"
VIEWPORT = {"width": 1280, "height": 800}
WAIT_S = 30.0


# -- fixtures -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    state = tmp_path_factory.mktemp("station-up")
    running = start_up(
        state,
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
def microphone(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The file the fake microphone plays; a test writes what the person says into it."""
    path = tmp_path_factory.mktemp("microphone") / "microphone.wav"
    path.write_bytes(Audio.silence(1.0).to_wav())
    return path


@pytest.fixture(scope="module")
def browser(microphone: Path) -> Iterator[Browser]:
    with sync_playwright() as playwright:
        launched = launch(playwright, microphone=microphone)
        try:
            yield launched
        finally:
            launched.close()


@pytest.fixture
def station(browser: Browser, up: Up) -> Iterator[Page]:
    """The station's page, connected and showing both robots; no errors allowed on it."""
    context = browser.new_context(viewport=VIEWPORT, permissions=["microphone"])
    page = context.new_page()
    watch = Watch(page)
    page.goto(up.endpoints["station"] + "?metrics=1")
    page.locator('#link-state[data-state="live"]').wait_for(timeout=WAIT_S * 1000)
    page.locator('.robot-row[data-status="idle"]').first.wait_for(timeout=WAIT_S * 1000)
    try:
        yield page
    finally:
        context.close()
    assert watch.problems == [], "the page logged errors or had failed requests"


# -- helpers ------------------------------------------------------------------------------


def reported(up: Up, thing: str) -> dict[str, Any]:
    with urllib.request.urlopen(up.endpoints["api"] + "/vahr/status", timeout=10) as answer:
        state: dict[str, Any] = json.loads(answer.read())["robots"][thing]
        return state


def eventually(check: Callable[[], Any], what: str, timeout_s: float = WAIT_S) -> Any:
    """`check()`'s first truthy result within `timeout_s`, else fail naming `what`."""
    deadline = time.monotonic() + timeout_s
    while True:
        result = check()
        if result:
            return result
        if time.monotonic() > deadline:
            pytest.fail(f"not within {timeout_s:g} s: {what}")
        time.sleep(0.1)


def drawn(page: Page, thing: str) -> dict[str, float]:
    position: dict[str, float] = page.evaluate(
        "(thing) => window.vahrStation.map.drawnPosition(thing)", thing
    )
    return position


def drawn_at(page: Page, thing: str, pose: dict[str, float], tolerance: float = 0.05) -> bool:
    at = drawn(page, thing)
    return math.hypot(at["x"] - pose["x"], at["y"] - pose["y"]) <= tolerance


def at_rest(up: Up, thing: str) -> dict[str, Any]:
    return eventually(
        lambda: (state := reported(up, thing))["status"] in ("idle", "stopped") and state,
        f"{thing} at rest",
    )


def shown(page: Page, thing: str) -> list[dict[str, Any]]:
    history: list[dict[str, Any]] = page.evaluate(
        "(thing) => window.vahrMetrics.shown.filter((s) => s.thing === thing)", thing
    )
    return history


def zone_pose(up: Up, zone: str) -> dict[str, float]:
    with urllib.request.urlopen(up.endpoints["station"] + "api/snapshot", timeout=10) as answer:
        zones = json.loads(answer.read())["fleet"]["zones"]
    pose: dict[str, float] = next(z["pose"] for z in zones if z["id"] == zone)
    return pose


def screenshot(page: Page, selector: str, name: str) -> None:
    IMAGES.mkdir(parents=True, exist_ok=True)
    page.locator(selector).screenshot(path=str(IMAGES / name), animations="disabled")


# -- the map ------------------------------------------------------------------------------


def test_the_map_shows_both_robots_at_their_reported_poses(up: Up, station: Page) -> None:
    for thing in ("placebot1", "placebot2"):
        # Given a robot at rest, as its shadow reports it
        pose = at_rest(up, thing)["pose"]
        # Then the page draws it there, and its row says where it is
        eventually(
            lambda thing=thing, pose=pose: drawn_at(station, thing, pose),
            f"{thing} drawn at {pose}",
        )
        row = station.locator(f'.robot-row[data-thing="{thing}"]')
        assert row.locator(".presence").inner_text() == "online"
    # And the floor has its zones, arms, conveyor and LED, drawn from fleet.yaml
    assert station.locator("#map .zone").count() == 5
    assert station.locator("#map .arm").count() == 5
    assert station.locator("#map .conveyor").count() == 1
    assert station.locator("#map .led").count() == 1
    screenshot(station, ".map-card", "station-map.png")


def test_the_station_of_vahr_up_shows_the_fleet_task_queue(up: Up, station: Page) -> None:
    # Given vahr up, whose dispatcher serves the fleet's task queue
    # Then its station shows the queue's card, empty while nobody asked for a task
    station.locator("#tasks").wait_for(state="visible", timeout=15_000)
    assert station.locator("#task-count").inner_text().startswith("0 queued")


def test_a_vahr_say_command_moves_a_robot_on_the_page_as_its_shadow_changes(
    up: Up, station: Page
) -> None:
    at_rest(up, "placebot1")
    # When a person tells the assistant (vahr say) to send placebot one to the loading zone
    turn = say(up.endpoints["api"], "send robot one to the loading zone")
    assert turn["intent"] == "NavigateIntent" and len(turn["commands"]) == 1
    # Then the page shows it driving, then loaded by the arm, as the shadow reports
    loaded = eventually(
        lambda: (state := reported(up, "placebot1")).get("cargo") and state["status"] == "idle",
        "placebot1 loaded at LOADING",
    )
    assert loaded
    eventually(
        lambda: drawn_at(station, "placebot1", zone_pose(up, "LOADING")),
        "placebot1 drawn at the loading zone",
    )
    row = station.locator('.robot-row[data-thing="placebot1"]')
    eventually(lambda: "package" in row.locator(".facts").inner_text(), "the package shown")
    statuses = [s["status"] for s in shown(station, "placebot1")]
    assert "navigating" in statuses and "loading" in statuses
    assert statuses.index("navigating") < statuses.index("loading")
    # When it is sent on to zone B, the arm there unloads it
    say(up.endpoints["api"], "send robot one to zone b")
    eventually(
        lambda: (
            (state := reported(up, "placebot1")).get("zone") == "B"
            and state["status"] == "idle"
            and not state.get("cargo")
        ),
        "placebot1 unloaded at B",
    )
    eventually(lambda: drawn_at(station, "placebot1", zone_pose(up, "B")), "drawn at B")
    eventually(lambda: "no package" in row.locator(".facts").inner_text(), "no package shown")
    last = shown(station, "placebot1")[-1]
    assert (last["status"], last["zone"], last["cargo"]) == ("idle", "B", False)
    # And the conversation shows both exchanges with the robot's acknowledgment
    entries = station.locator("#conversation .entry.turn")
    eventually(lambda: entries.count() >= 2, "both turns in the conversation")
    assert "acknowledged in" in entries.last.locator(".meta").inner_text()


# -- the keyboard-and-mouse panel and the experiment ---------------------------------------


def test_a_click_on_a_robot_then_a_zone_sends_a_navigate_and_logs_the_clicks(
    up: Up, station: Page, tmp_path: Path
) -> None:
    at_rest(up, "placebot2")
    # Given a keyboard-and-mouse session of the experiment running against the system
    experiment = spawn(
        [*VAHR, "experiment", "--participant", "P07", "--method", "keyboard", "--trial", "1",
         "--log-dir", str(tmp_path), "--broker", up.endpoints["mqtt"],
         "--api", up.endpoints["api"], "--task-timeout", "120"],
        started_for=tmp_path, cwd=ROOT, env=clean_env(), stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        # The page shows the participant's briefing and the judge's verdicts
        station.locator("#experiment").wait_for(timeout=WAIT_S * 1000)
        station.locator("#verdicts li.running").wait_for(timeout=WAIT_S * 1000)
        briefing = station.locator("#briefing").inner_text()
        assert "P07" in briefing and "Task I zones" in briefing
        assert "Weather: ask the assistant" in briefing  # the keyboard method asks for it
        # When the participant clicks placebot two on the map, then the loading zone
        station.locator('#map .robot[data-thing="placebot2"] .robot-body').click()
        station.locator('#map .zone[data-zone="LOADING"] .zone-body').click()
        # Then the robot acknowledges a navigate command sent by the console
        status = station.locator("#panel-status")
        eventually(lambda: "acknowledged by placebot two" in status.inner_text(), "the ack")
        command = station.evaluate(
            "() => Object.values(window.vahrStation.store.commands).find("
            "(c) => c.source === 'console' && c.params.zone === 'LOADING')"
        )
        assert command["action"] == "navigate" and command["target"] == "placebot2"
        assert command["acks"]["placebot2"]["event"] in ("accepted", "done")
        eventually(lambda: reported(up, "placebot2").get("zone") == "LOADING", "placebot2 there")
        screenshot(station, ".panel-card", "station-panel.png")
        screenshot(station, "#experiment", "station-experiment.png")
    finally:
        # The observer ends the session (end of input ends each task)
        assert experiment.stdin is not None
        experiment.stdin.close()
        experiment.wait(timeout=60)
    assert experiment.returncode == 0, experiment.stderr.read() if experiment.stderr else ""
    at_rest(up, "placebot2")
    # And the session's log holds both clicks as interactions, the second with its command
    (log_file,) = tmp_path.glob("P07-keyboard-trial1.sqlite")
    entries = read_log(log_file)
    started = {e.data["id"]: e for e in entries if e.kind == Kind.INTERACTION_STARTED}
    ended = [e for e in entries if e.kind == Kind.INTERACTION_ENDED and e.data["id"] in started]
    texts = [e.data["text"] for e in ended]
    assert "click robot placebot2" in texts and "click zone LOADING" in texts
    zone_click = next(e for e in ended if e.data["text"] == "click zone LOADING")
    assert zone_click.data["commands"] == [command["id"]]
    assert zone_click.data["channel"] == "click" and zone_click.task == "I"
    assert started[zone_click.data["id"]].at <= zone_click.at
    robot_click = next(e for e in ended if e.data["text"] == "click robot placebot2")
    assert robot_click.data.get("counts") is False  # selecting sends nothing by design
    # And the page no longer shows the session
    station.locator("#experiment").wait_for(state="hidden", timeout=WAIT_S * 1000)


# -- push-to-talk -------------------------------------------------------------------------


def hold_to_talk(page: Page, seconds: float) -> dict[str, Any]:
    """Hold the talk button for `seconds`, let go, and return what the page measured."""
    before = page.evaluate("() => window.vahrMetrics.ptt.length")
    box = page.locator("#talk").bounding_box()
    assert box is not None
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.down()
    time.sleep(seconds)
    page.mouse.up()
    page.wait_for_function(
        "(n) => window.vahrMetrics.ptt.length > n", arg=before, timeout=WAIT_S * 1000
    )
    result: dict[str, Any] = page.evaluate("() => window.vahrMetrics.ptt.at(-1)")
    return result


def test_push_to_talk_moves_placebot_two_and_silence_changes_nothing(
    up: Up, station: Page, microphone: Path
) -> None:
    at_rest(up, "placebot2")
    # Given the microphone hears "send placebot two to zone c", spoken by espeak-ng
    spoken = EspeakSynthesizer().synthesize("send placebot two to zone c")
    clip = Audio(Audio.silence(0.4).pcm + spoken.pcm + Audio.silence(0.6).pcm)
    microphone.write_bytes(clip.to_wav())
    # When the operator holds the button while it plays
    heard = hold_to_talk(station, clip.seconds + 0.4)
    # Then the page shows the transcript and the reply, and placebot two goes to zone C
    assert heard["transcript"] == "send placebot two to zone c"
    state = station.locator("#talk-state").inner_text()
    assert "send placebot two to zone c" in state
    assert "Placebot two is on its way to zone C" in state
    eventually(
        lambda: (s := reported(up, "placebot2")).get("zone") == "C" and s["status"] == "idle",
        "placebot2 at C",
    )
    turn = station.locator("#conversation .entry.turn").last
    eventually(lambda: "acknowledged in" in turn.inner_text(), "the turn's acknowledgment")
    assert "You, by voice" in turn.inner_text() and "sure" in turn.inner_text()
    screenshot(station, ".conversation-card", "station-conversation.png")
    before = reported(up, "placebot2")["last_command"]
    commands = station.evaluate("() => Object.keys(window.vahrStation.store.commands).length")

    # Given the microphone hears nothing but silence
    microphone.write_bytes(Audio.silence(2.5).to_wav())
    # When the operator holds the button for two seconds
    nothing = hold_to_talk(station, 2.0)
    # Then the page says it did not catch that, and nothing was sent to any robot
    assert nothing["transcript"] == ""
    assert "Sorry, I didn't catch that." in station.locator("#talk-state").inner_text()
    time.sleep(0.5)
    assert reported(up, "placebot2")["last_command"] == before
    after = station.evaluate("() => Object.keys(window.vahrStation.store.commands).length")
    assert after == commands


# -- the whole page, then a robot going away ------------------------------------------------


def test_the_page_loads_without_errors_and_reads_well_at_two_sizes(up: Up, station: Page) -> None:
    # The page's own files, the favicon included, all load (the fixture fails on any error)
    icons = station.evaluate(
        "() => [...document.querySelectorAll('link[rel=icon]')].map((l) => l.href)"
    )
    assert icons and all(icon.endswith("/static/favicon.svg") for icon in icons)
    with urllib.request.urlopen(icons[0], timeout=10) as answer:
        assert answer.headers["Content-Type"] == "image/svg+xml"
    station.locator("#robots-title").click()  # focus leaves the buttons
    IMAGES.mkdir(parents=True, exist_ok=True)
    station.screenshot(path=str(IMAGES / "station.png"), animations="disabled")
    station.set_viewport_size({"width": 820, "height": 1180})
    station.screenshot(path=str(IMAGES / "station-tablet.png"), animations="disabled")
    # On a tablet the columns stack: the map comes first, as wide as the screen
    map_box = station.locator(".map-card").bounding_box()
    assert map_box is not None and map_box["width"] > 700


def test_a_robot_whose_agent_stops_shows_offline(up: Up, station: Page) -> None:
    # Runs last in this module: stopping a robot ends the shared `vahr up`.
    row = station.locator('.robot-row[data-thing="placebot2"]')
    assert row.locator(".presence").inner_text() == "online"
    agent = _agent_pid(up, "placebot2")
    # When placebot two's agent stops
    os.kill(agent, signal.SIGTERM)
    # Then the page shows it offline, greyed out on the map, with when it was last seen
    eventually(lambda: "offline" in row.locator(".presence").inner_text(), "offline", 10.0)
    assert "seen" in row.locator(".presence").inner_text()
    robot = station.locator('#map .robot[data-thing="placebot2"]')
    assert "offline" in (robot.get_attribute("class") or "")
    assert (
        "last seen"
        in station.locator('#map .robot[data-thing="placebot2"] .robot-detail').text_content()
        or ""
    )


def _agent_pid(up: Up, thing: str) -> int:
    """The `robot-agent run --thing THING` process `vahr up` started."""
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            argv = (proc / "cmdline").read_bytes().split(b"\0")
            parent = int((proc / "stat").read_text().split(") ", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        if (
            parent == up.process.pid
            and b"--thing" in argv
            and argv[argv.index(b"--thing") + 1] == thing.encode()
        ):
            return int(proc.name)
    raise AssertionError(f"no robot-agent process for {thing}")
