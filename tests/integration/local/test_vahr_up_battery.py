"""A shift's batteries on `vahr up`, as the operator meets them, with a fleet of its own
(three rovers and one charger, tests/fleets/three_rovers.yaml): every robot reports its
battery; a robot set to 12% goes to the charger by itself and is announced; a robot sent to
a zone is never the low one, though it is nearest; "how much battery does rover one have"
is answered with a number; a robot out of service is not picked and does not move when
named; back in service it is picked. Bad input is one line and changes nothing."""

from __future__ import annotations

import re
import subprocess
import time
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.fleets import THREE_ROVERS
from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, say, start_up, stop_up
from vahr.plumbing.client import call

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

SPEED = 20


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    running = start_up(
        tmp_path_factory.mktemp("rovers"), "--fleet", str(THREE_ROVERS),
        "--sim-speed-factor", str(SPEED), "--station-port", "0", "--mqtt-port", "0",
    )  # fmt: skip
    try:
        yield running
    finally:
        stop_up(running.process)


def reported(up: Up, thing: str) -> dict[str, Any]:
    shadow = call(up.endpoints["api"], "GET", f"/things/{thing}/shadow")
    state: dict[str, Any] = shadow["state"]["reported"]
    return state


def wait_for(condition: Callable[[], Any], timeout_s: float = 20.0) -> Any:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if found := condition():
            return found
        time.sleep(0.1)
    raise AssertionError("timed out")


def fault(up: Up, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*VAHR, "fault", *argv, "--api", up.endpoints["api"]],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
    )  # fmt: skip


def idle(up: Up, thing: str) -> bool:
    state = reported(up, thing)
    return state.get("status") == "idle" and (state.get("last_command") or {}).get("result") in (
        None,
        "done",
    )


NAMES = {"Rover one": "rover1", "Rover two": "rover2", "Rover three": "rover3"}


def holder(up: Up, turn: dict[str, Any]) -> str:
    """The robot the dispatcher gave the turn's task to, as the reply names it, checked
    against the task list the dispatcher serves."""
    match = re.match(r"(Rover \w+) is on its way to ", turn["speech"])
    assert match, turn["speech"]
    thing = NAMES[match.group(1)]
    tasks = call(up.endpoints["api"], "GET", "/vahr/tasks")["tasks"]
    assert thing in [task["thing"] for task in tasks if task["status"] == "assigned"] or idle(
        up, thing
    )
    return thing


def test_a_shift_with_batteries_charging_and_a_robot_out_of_service(up: Up) -> None:
    api = up.endpoints["api"]
    # Every robot reports its battery.
    for thing in ("rover1", "rover2", "rover3"):
        battery = wait_for(lambda t=thing: reported(up, t).get("battery"))
        assert set(battery) == {"percent", "charging"} and 90 <= battery["percent"] <= 100

    # Rover one, set to 12 %, sets off for the charger by itself, and is announced.
    done = fault(up, "rover1", "battery", "12")
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "rover1's battery is at 12 %"
    going = wait_for(lambda: reported(up, "rover1").get("destination") == "DOCK" or None)
    assert going
    told = wait_for(
        lambda: [
            a
            for a in call(api, "GET", "/vahr/announcements")["announcements"]
            if a["kind"] == "battery_low"
        ]
    )
    assert told[0]["thing"] == "rover1"
    assert told[0]["speech"] == "Rover one is low on battery and is going to charge."

    # "send a robot to zone a" does not pick it, though it is the nearest to zone A.
    turn = say(api, "Alexa, ask robot fleet to send a robot to zone a")
    assert holder(up, turn) == "rover2"
    assert "rover one" not in turn["speech"].lower()

    # Its battery is answered with a number.
    asked = say(api, "Alexa, ask robot fleet how much battery does rover one have")
    assert asked["intent"] == "BatteryIntent"
    said = re.fullmatch(
        r"Rover one has (\d+) percent battery( and is charging)?\.", asked["speech"]
    )
    assert said and 11 <= int(said.group(1)) <= 100, asked["speech"]
    # At the charger, it charges.
    assert wait_for(lambda: (reported(up, "rover1").get("battery") or {}).get("charging"))

    # Rover two, out of service: not picked, and it does not move when named.
    wait_for(lambda: idle(up, "rover2"))
    out = say(api, "Alexa, ask robot fleet to take rover two out of service")
    assert out["intent"] == "OutOfServiceIntent"
    assert out["speech"] == "Rover two is out of service now and gets no tasks."
    assert call(api, "GET", "/vahr/service") == {"out_of_service": ["rover2"]}
    turn = say(api, "Alexa, ask robot fleet to send a robot to zone a")
    assert holder(up, turn) == "rover3"
    before = reported(up, "rover2")
    named = say(api, "Alexa, ask robot fleet to send rover two to zone b")
    assert named["speech"] == "Rover two is out of service, so I sent nothing."
    assert named["commands"] == []
    time.sleep(1.0)
    after = reported(up, "rover2")
    assert (after["pose"], after["last_command"]) == (before["pose"], before["last_command"])

    # Back in service, it is picked: the nearest robot to zone A, where it stands.
    wait_for(lambda: idle(up, "rover3"))
    back = say(api, "Alexa, ask robot fleet to put rover two back in service")
    assert back["speech"] == "Rover two is back in service."
    turn = say(api, "Alexa, ask robot fleet to send a robot to zone a")
    assert holder(up, turn) == "rover2"


def test_a_charge_that_is_not_one_or_a_robot_not_in_the_fleet_is_one_line(up: Up) -> None:
    before = reported(up, "rover3").get("battery")
    for argv, words in (
        (("rover3", "battery", "120"), "battery 120: a charge is 0 to 100 percent"),
        (("rover3", "battery", "-1"), "a charge is 0 to 100 percent"),
        (("rover9", "battery", "50"), "rover9 is not a robot of the fleet"),
    ):
        done = fault(up, *argv)
        assert done.returncode != 0
        assert words in done.stderr and done.stderr.count("\n") == 1, done.stderr
    assert reported(up, "rover3").get("battery") == before
