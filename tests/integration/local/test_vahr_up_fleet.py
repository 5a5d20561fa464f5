"""`vahr up --fleet FILE` as a user meets it: a made-up fleet of six robots runs, is
understood by voice and drawn by the station, commands beside the stack learn it, and a
broken fleet file is one line and exit code 2 with nothing started."""

from __future__ import annotations

import subprocess
import time
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.fleets import BAD_FLEETS, SIX_ROBOTS, bad_fleet
from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, say, start_up, stop_up
from vahr.domain import load_fleet
from vahr.plumbing.client import call
from vahr.plumbing.ports import free_port
from vahr.twin.recovery import started_for

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

BIRDS = ["kestrel", "heron", "osprey", "plover", "curlew", "dunlin"]
UNFIT = (
    "the paper's tasks need two robots and delivery zones A, C and D (zones with arm: "
    "unloader); this fleet lacks delivery zones A, C and D"
)


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    state = tmp_path_factory.mktemp("six")
    running = start_up(state, "--fleet", str(SIX_ROBOTS), "--sim-speed-factor", "20")
    try:
        yield running
    finally:
        stop_up(running.process)


def reported(up: Up, thing: str) -> dict[str, Any]:
    shadow = call(up.endpoints["api"], "GET", f"/things/{thing}/shadow")
    state: dict[str, Any] = shadow["state"]["reported"]
    return state


def eventually(check: Callable[[], bool], timeout_s: float = 20.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while not check():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


def test_the_running_stack_serves_the_fleet_it_runs(up: Up) -> None:
    # When a command asks the running stack for its fleet
    fleet = call(up.endpoints["api"], "GET", "/vahr/fleet")["fleet"]
    # Then it names the six robots of the file, its zones and its group
    assert [robot["thing"] for robot in fleet["robots"]] == BIRDS
    assert [zone["id"] for zone in fleet["zones"]] == ["LOADING", "PANTRY", "OVEN", "SHOP"]
    assert fleet["groups"][1] == {
        "id": "waders",
        "spoken": ["the waders", "waders"],
        "robots": ["plover", "curlew", "dunlin"],
    }
    status = call(up.endpoints["api"], "GET", "/vahr/status")
    assert status["online"] == dict.fromkeys(BIRDS, True)


def test_each_robot_starts_where_the_file_puts_it(up: Up) -> None:
    starts = {robot.thing: robot.start for robot in load_fleet(SIX_ROBOTS).robots}
    for thing, start in starts.items():
        pose = {"x": start.x, "y": start.y, "theta": start.theta}
        assert eventually(lambda t=thing, p=pose: reported(up, t).get("pose") == p), thing


def test_a_spoken_command_sends_a_made_up_robot_to_a_made_up_zone(up: Up) -> None:
    # When the person asks for the heron to go to the pantry
    turn = say(up.endpoints["api"], "Alexa, ask robot fleet to send heron to the pantry")
    # Then the simulator knew both names, and the skill published one command
    assert turn["intent"] == "NavigateIntent"
    assert turn["slots"]["robot"] == {"value": "heron", "id": "heron"}
    assert turn["slots"]["zone"] == {"value": "the pantry", "id": "PANTRY"}
    assert len(turn["commands"]) == 1
    assert turn["speech"].startswith("Heron is on its way to the pantry")
    # And the heron's shadow reports it in the pantry, at the zone's pose, and no one else moved
    assert eventually(lambda: reported(up, "heron").get("zone") == "PANTRY"), reported(up, "heron")
    assert reported(up, "heron")["pose"] == {"x": 20.0, "y": 12.0, "theta": 0.0}
    assert reported(up, "kestrel")["pose"] == {"x": 2.0, "y": 2.0, "theta": 0.0}


def test_the_station_draws_the_files_floor_and_robots(up: Up) -> None:
    snapshot = call(up.endpoints["station"].rstrip("/"), "GET", "/api/snapshot")
    view = snapshot["fleet"]
    assert [robot["thing"] for robot in view["robots"]] == BIRDS
    assert (view["floor"]["width"], view["floor"]["height"]) == (24.0, 14.0)


def test_the_experiment_beside_the_stack_learns_its_fleet_and_says_what_it_lacks(
    up: Up, tmp_path: Path
) -> None:
    # When the experiment is pointed at the stack, with no --fleet of its own
    result = subprocess.run(
        [*VAHR, "experiment", "--api", up.endpoints["api"], "--participant", "P01",
         "--method", "vahr", "--trial", "1", "--log-dir", str(tmp_path), "--plan-only"],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    # Then it judged the six birds, not the bundled placebots, and refused in one line
    assert (result.returncode, result.stderr) == (2, f"vahr experiment: error: {UNFIT}\n")
    assert list(tmp_path.iterdir()) == []


def test_the_experiment_given_an_unfit_fleet_file_says_what_it_needs(tmp_path: Path) -> None:
    result = subprocess.run(
        [*VAHR, "experiment", "--fleet", str(SIX_ROBOTS), "--participant", "P01",
         "--method", "keyboard", "--trial", "1", "--log-dir", str(tmp_path), "--no-shadow"],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert (result.returncode, result.stderr) == (2, f"vahr experiment: error: {UNFIT}\n")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", sorted(BAD_FLEETS))
def test_a_broken_fleet_file_starts_nothing(name: str, tmp_path: Path) -> None:
    # Given a fleet file with one mistake
    path, state = bad_fleet(name), tmp_path / "state"
    # When vahr up is given it
    result = subprocess.run(
        [*VAHR, "up", "--fleet", str(path), "--state-dir", str(state), "--no-voice",
         "--api-port", str(free_port()), "--mqtts-port", str(free_port()),
         "--station-port", str(free_port())],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    # Then it says in one line which entry is wrong and why, and exits 2
    assert result.returncode == 2
    assert result.stderr == f"vahr up: error: {path}: {BAD_FLEETS[name]}\n"
    assert result.stdout == ""
    # and nothing started: no state directory, no process left for it
    assert not state.exists()
    assert started_for(state) == []
