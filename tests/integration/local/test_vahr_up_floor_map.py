"""`vahr up --fleet` on a map of its own, as a user meets it: two rooms with a wall between
them and a gap at its top. "send a robot to zone a" picks the robot nearer by path, not the
one nearer in a straight line; a robot sent round the wall is never reported inside it and
arrives; a closed zone moves nobody and the reply says so; an opened one works again. The
station (real headless Chromium) draws the map under the robots, a moving robot's path, and
closes and opens a zone with its switch. A bad map, or a zone in a wall, stops `vahr up` in
one line with nothing started. The station test writes docs/images/station-floor-map.png."""

from __future__ import annotations

import subprocess
import time
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest
from playwright.sync_api import sync_playwright

from tests.support.browser import Watch, launch
from tests.support.floor_maps import OCCUPIED, two_rooms, write_map
from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, say, start_up, stop_up
from vahr.navigation import load_map
from vahr.plumbing.client import call
from vahr.plumbing.ports import free_port
from vahr.twin.recovery import started_for

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from tests.support.floor_maps import TwoRooms


@pytest.fixture(scope="module")
def rooms(tmp_path_factory: pytest.TempPathFactory) -> TwoRooms:
    return two_rooms(tmp_path_factory.mktemp("two-rooms"))


@pytest.fixture(scope="module")
def up(rooms: TwoRooms, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    state = tmp_path_factory.mktemp("state")
    running = start_up(state, "--fleet", str(rooms.fleet_file), "--sim-speed-factor", "4")
    try:
        yield running
    finally:
        stop_up(running.process)


def dispatched(up: Up, zone: str) -> str:
    """The id of the command the dispatcher sent for its task to `zone` (the task's id)."""
    tasks = call(up.endpoints["api"], "GET", "/vahr/tasks")["tasks"]
    [task] = [task for task in tasks if task["zone"] == zone and task["status"] == "assigned"]
    return str(task["id"])


def drive(up: Up, command_id: str) -> list[dict[str, Any]]:
    """The robot's events for `command_id` until it arrived (the last one)."""
    events = []
    while True:
        event = up.lines.get(timeout=60)
        if event.get("command_id") != command_id:
            continue
        events.append(event)
        assert event["event"] not in ("failed", "stuck", "rejected"), event
        if event["event"] == "arrived":
            return events


def test_the_robot_nearer_by_path_goes_and_one_sent_round_the_wall_never_enters_it(
    up: Up, rooms: TwoRooms
) -> None:
    api = up.endpoints["api"]
    # Given the left rover 1.7 m from zone A through the wall, the right one 4.4 m away
    # When a robot is asked for without a name
    turn = say(api, "send a robot to zone a")
    # Then the right rover goes: nearer by path (4.4 m against about 7 m round the wall)
    assert turn["speech"] == "Rover two is on its way to zone A."
    assert drive(up, dispatched(up, "A"))[-1]["thing"] == "right"
    # When the left rover is sent there by name
    turn = say(api, "send rover one to zone a")
    [command_id] = turn["commands"]
    events = drive(up, command_id)
    # Then every pose it reported on the way is on free ground, none inside the wall
    grid = load_map(rooms.map_file)
    poses = [event["pose"] for event in events if event.get("pose")]
    assert len(poses) >= 4, events
    for pose in poses:
        cell = grid.cell(pose["x"], pose["y"])
        assert cell is not None and grid.free[cell], f"reported at {pose}, not on free ground"
        assert not (
            rooms.wall_left <= pose["x"] <= rooms.wall_right and pose["y"] < rooms.gap_bottom
        )
    # and it went through the gap (the way round) and arrived at zone A
    assert max(pose["y"] for pose in poses) > rooms.gap_bottom
    arrived = events[-1]
    assert arrived["zone"] == "A"
    # And its shadow says where it is, with no path left to drive (the shadow's update and
    # the event are two messages: the update may come a moment after)
    deadline = time.monotonic() + 10.0
    while True:
        reported = call(api, "GET", "/things/left/shadow")["state"]["reported"]
        if reported.get("zone") == "A" or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    assert (reported.get("zone"), reported.get("path")) == ("A", None)


def test_a_closed_zone_moves_nobody_and_the_reply_says_so_until_it_opens(up: Up) -> None:
    api = up.endpoints["api"]
    # When zone B is closed
    turn = say(api, "close zone b")
    assert turn["speech"] == "Zone B is closed. No robot will be sent there until it opens."
    assert call(api, "GET", "/vahr/zones") == {"closed": ["B"]}
    # Then no robot is sent there, by name or not, and the reply says why
    for utterance in ("send rover one to zone b", "send a robot to zone b"):
        turn = say(api, utterance)
        assert turn["speech"] == "Zone B is closed, so I sent no robot there.", utterance
        assert turn["commands"] == []
    assert call(api, "GET", "/vahr/tasks")["tasks"] == []
    # When it is opened again
    turn = say(api, "open zone b")
    assert turn["speech"] == "Zone B is open again."
    # Then a robot goes there again
    turn = say(api, "send a robot to zone b")
    assert turn["speech"].endswith("is on its way to zone B.")
    assert drive(up, dispatched(up, "B"))[-1]["zone"] == "B"


def test_the_station_draws_the_map_a_robots_path_and_a_zone_it_closes(up: Up) -> None:
    api, station = up.endpoints["api"], up.endpoints["station"]
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 800})
            watch = Watch(page)
            page.goto(station)
            page.locator('#link-state[data-state="live"]').wait_for(timeout=15_000)
            # The map is drawn at its scale: 10 m by 5 m from the origin, its picture loaded
            image = page.locator("image.floor-map")
            assert image.get_attribute("href") == "/api/map.png"
            assert [image.get_attribute(a) for a in ("x", "y", "width", "height")] == [
                "0", "-5", "10", "5"
            ]  # fmt: skip
            size = page.evaluate(
                "fetch('/api/map.png').then(r => r.blob()).then(createImageBitmap)"
                ".then(b => [b.width, b.height])"
            )
            assert size == [200, 100]
            # When the left rover is sent to the zone in the other room
            where = call(api, "GET", "/things/left/shadow")["state"]["reported"]["pose"]
            other = "a" if where["x"] < 5.0 else "b"
            turn = say(api, f"send rover one to zone {other}")
            [command_id] = turn["commands"]
            # Then its path is drawn ahead of it, round the wall: more than one leg
            path = page.locator("polyline.path[visibility=visible]")
            path.wait_for(timeout=15_000)
            assert len((path.get_attribute("points") or "").split()) >= 3
            page.screenshot(path=str(ROOT / "docs/images/station-floor-map.png"))
            drive(up, command_id)
            # When zone B's switch is pressed, zone B is closed and drawn so
            page.locator('#zone-switches button[data-zone="B"]').click()
            page.locator('g.zone.closed[data-zone="B"]').wait_for(timeout=15_000)
            assert call(api, "GET", "/vahr/zones") == {"closed": ["B"]}
            # and pressed again, it opens
            page.locator('#zone-switches button[data-zone="B"][aria-pressed="true"]').click()
            page.locator('g.zone.closed[data-zone="B"]').wait_for(state="detached", timeout=15_000)
            assert call(api, "GET", "/vahr/zones") == {"closed": []}
            assert watch.problems == []
        finally:
            browser.close()


def up_with(fleet: Path, state: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*VAHR, "up", "--fleet", str(fleet), "--state-dir", str(state), "--no-voice",
         "--api-port", str(free_port()), "--mqtts-port", str(free_port()),
         "--station-port", str(free_port())],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip


def test_a_zone_in_a_wall_or_a_map_without_its_image_starts_nothing(tmp_path: Path) -> None:
    rooms = two_rooms(tmp_path)
    # Given zone A moved into the wall between the rooms
    in_wall = tmp_path / "in-wall.yaml"
    in_wall.write_text(
        rooms.fleet_file.read_text().replace("{x: 6.0, y: 0.8, theta: 0.0}", "{x: 5.0, y: 1.0}")
    )
    result = up_with(in_wall, tmp_path / "state")
    # Then vahr up says which zone and why in one line, exits 2 and starts nothing
    assert result.returncode == 2
    assert result.stderr == (
        f"vahr up: error: {in_wall}: zones.1.pose: (5, 1) is inside a wall on the map "
        "two-rooms.yaml, so no robot can reach it\n"
    )
    assert not (tmp_path / "state").exists() and started_for(tmp_path / "state") == []
    # Given a map whose image is missing
    shades = np.full((20, 20), OCCUPIED, dtype=np.uint8)
    lonely = write_map(tmp_path, shades, name="lonely")
    (tmp_path / "lonely.pgm").unlink()
    fleet = tmp_path / "lonely-fleet.yaml"
    fleet.write_text(rooms.fleet_file.read_text().replace("two-rooms.yaml", lonely.name))
    result = up_with(fleet, tmp_path / "state")
    assert result.returncode == 2
    assert result.stderr == (
        f"vahr up: error: {fleet}: map {lonely}: image lonely.pgm: no such file "
        f"(looked at {tmp_path / 'lonely.pgm'})\n"
    )
