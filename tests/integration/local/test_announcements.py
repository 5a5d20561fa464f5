"""Announcements on the local stack, end to end: `vahr fault` makes a running simulated robot
stuck or offline, and the assistant tells it once (`GET /vahr/announcements`)."""

from __future__ import annotations

import json
import subprocess
import time
from typing import TYPE_CHECKING, Any

import pytest
from support.vahr_up import ROOT, VAHR, Up, clean_env, start_up, stop_up
from support.vahr_up import say as say_to

from vahr.plumbing.client import call

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

SPEED = 20


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    # No station (it is not under test here), and every port free: never the defaults
    # another `vahr up` on this machine may hold.
    running = start_up(
        tmp_path_factory.mktemp("up"), "--mqtt-port", "0", "--station-port", "0",
        "--sim-speed-factor", str(SPEED),
    )  # fmt: skip
    try:
        yield running
    finally:
        stop_up(running.process)


def fault(up: Up, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*VAHR, "fault", *argv, "--api", up.endpoints["api"]],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
    )  # fmt: skip


def announcements(up: Up) -> list[dict[str, Any]]:
    found: list[dict[str, Any]] = call(up.endpoints["api"], "GET", "/vahr/announcements")[
        "announcements"
    ]
    return found


def wait_for(condition: Callable[[], Any], timeout_s: float = 20.0) -> Any:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if found := condition():
            return found
        time.sleep(0.1)
    raise AssertionError("timed out")


def test_health_tells_the_robots_speed_factor(up: Up) -> None:
    assert call(up.endpoints["api"], "GET", "/vahr/health") == {
        "ok": True, "ready": True, "sim_speed_factor": SPEED,
    }  # fmt: skip


def test_a_robot_made_stuck_is_announced_once_naming_it_and_its_goal(up: Up) -> None:
    # Given placebot1 told to get stuck, then sent to zone B
    done = fault(up, "placebot1", "stuck")
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().startswith("placebot1 is stuck")
    turn = say_to(up.endpoints["api"], "alexa ask robot fleet to send placebot one to zone b")
    [command] = turn["commands"]
    # When it stops half way and the executor gives up on it
    stuck = up.wait_event(command, "stuck", timeout_s=30)
    assert stuck["event"] in ("stuck", "failed")
    told = wait_for(lambda: [a for a in announcements(up) if a["thing"] == "placebot1"])
    # Then the assistant told it once, in words, with the fault's kind and time
    time.sleep(1.0)
    told = [a for a in announcements(up) if a["thing"] == "placebot1"]
    assert [(a["kind"], a["speech"]) for a in told] == [
        ("stuck", "Placebot one is stuck on its way to zone B and needs your help.")
    ]
    assert set(told[0]) >= {"id", "time", "thing", "kind", "speech", "reason", "opened_at"}


def test_a_robot_taken_offline_is_announced_and_comes_back(up: Up) -> None:
    done = fault(up, "placebot2", "offline", "--offline-s", "2")
    assert done.returncode == 0, done.stderr
    told = wait_for(lambda: [a for a in announcements(up) if a["kind"] == "offline"])
    assert [a["speech"] for a in told] == ["Placebot two has gone offline."]
    # It reconnects by itself, and presence says so
    wait_for(lambda: call(up.endpoints["api"], "GET", "/vahr/status")["online"]["placebot2"])


def test_newest_is_last(up: Up) -> None:
    times = [a["time"] for a in announcements(up)]
    assert times == sorted(times)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ("placebot9", "stuck"),
            "placebot9 is not a robot of the fleet; robots are placebot1, placebot2",
        ),
        (("placebot1", "melt"), "argument fault: invalid choice: 'melt'"),
    ],
)
def test_bad_faults_are_one_line_errors(up: Up, argv: tuple[str, ...], message: str) -> None:
    done = fault(up, *argv)
    assert done.returncode != 0
    [line] = done.stderr.strip().splitlines()[-1:]
    assert message in line
    assert "Traceback" not in done.stderr


def test_fault_without_a_running_system_is_one_line() -> None:
    done = subprocess.run(
        [*VAHR, "fault", "placebot1", "stuck", "--api", "http://127.0.0.1:9"],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
    )  # fmt: skip
    assert done.returncode != 0
    assert done.stderr.startswith("vahr fault: error: nothing answers at http://127.0.0.1:9")
    assert json.dumps(done.stderr).count("\\n") == 1
