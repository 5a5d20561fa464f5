"""`vahr up --swarm N` as a user meets it: 200 simulated robots in one process on a floor
sized for them, "where are the robots" answered with a summary within the word bound,
"which robots are stuck?" after two robots were made stuck with `vahr fault`, and bad
--swarm values refused in one line with nothing started."""

from __future__ import annotations

import functools
import itertools
import subprocess
import time
from datetime import datetime
from typing import TYPE_CHECKING, Any

import boto3
import pytest

from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, say, start_up, stop_up
from vahr.plumbing.client import call

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

SIZE = 200
MAX_WORDS = 60


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    state = tmp_path_factory.mktemp("swarm")
    running = start_up(state, "--swarm", str(SIZE), "--sim-speed-factor", "20")
    try:
        yield running
    finally:
        stop_up(running.process)


def reported(up: Up, thing: str) -> dict[str, Any]:
    shadow = call(up.endpoints["api"], "GET", f"/things/{thing}/shadow")
    state: dict[str, Any] = shadow["state"]["reported"]
    return state


def is_stuck(up: Up, thing: str) -> bool:
    return bool(reported(up, thing)["status"] == "stuck")


def eventually(check: Callable[[], bool], timeout_s: float = 30.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while not check():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.2)
    return True


def test_the_swarm_runs_every_robot_of_a_generated_fleet(up: Up) -> None:
    fleet = call(up.endpoints["api"], "GET", "/vahr/fleet")["fleet"]
    things = [robot["thing"] for robot in fleet["robots"]]
    assert things == [f"rover{n}" for n in range(1, SIZE + 1)]
    assert fleet["robots"][16]["spoken"] == ["rover 17"]
    # The floor holds every robot's start, and no robot starts in a zone.
    floor = fleet["floor"]
    for robot in fleet["robots"]:
        assert 0 <= robot["start"]["x"] <= floor["width"]
        assert 0 <= robot["start"]["y"] <= floor["height"]
    online = call(up.endpoints["api"], "GET", "/vahr/status")["online"]
    assert sum(online.values()) == SIZE


def test_where_are_the_robots_is_a_summary_within_the_word_bound(up: Up) -> None:
    turn = say(up.endpoints["api"], "Alexa, ask robot fleet where are the robots")
    assert turn["intent"] == "StatusIntent"
    assert turn["speech"].startswith(f"Of {SIZE} robots, ")
    assert len(turn["speech"].split()) <= MAX_WORDS
    assert turn["latency_ms"] < 1000


def test_which_robots_are_stuck_after_two_faults(up: Up) -> None:
    api = up.endpoints["api"]
    for thing, zone in (("rover17", "c"), ("rover42", "a")):
        # When a fault is injected and the robot is then sent on its way
        fault = subprocess.run(
            [*VAHR, "fault", thing, "stuck", "--api", api],
            cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
        )  # fmt: skip
        assert fault.returncode == 0, fault.stderr
        turn = say(api, f"Alexa, ask robot fleet to send {thing[:5]} {thing[5:]} to zone {zone}")
        assert turn["slots"]["robot"]["id"] == thing, turn
    # Then both report stuck on the way
    for thing in ("rover17", "rover42"):
        assert eventually(functools.partial(is_stuck, up, thing)), reported(up, thing)
    # And the follow-up names them with where they are
    turn = say(api, "Alexa, ask robot fleet which robots are stuck")
    assert turn["intent"] == "ProblemRobotsIntent"
    assert turn["speech"].startswith("2 robots are stuck: rover 17 near zone ")
    assert " and rover 42 near zone " in turn["speech"]
    # And the summary counts them last, naming them after the counts
    summary = say(api, "Alexa, ask robot fleet where are the robots")["speech"]
    assert f"Of {SIZE} robots, " in summary
    assert "are stuck: rover 17 near zone " in summary
    assert len(summary.split()) <= MAX_WORDS
    # And one robot by name is one sentence, as for the paper's robots
    where = say(api, "Alexa, ask robot fleet where is rover 17")
    assert where["speech"].startswith("Rover 17 is stuck")


def test_a_robot_of_the_swarm_reports_its_progress_once_a_second(up: Up) -> None:
    # Given the swarm at 20 times real time, when rover 5 drives across the floor
    turn = say(up.endpoints["api"], "Alexa, ask robot fleet to send rover 5 to zone d")
    [command] = turn["commands"]
    drive: list[dict[str, Any]] = []
    while not drive or drive[-1]["event"] not in ("arrived", "failed"):
        line = up.lines.get(timeout=30)
        if line.get("command_id") == command:
            drive.append(line)
    # Then its progress came about once a wall-clock second (not once a simulated second,
    # twenty times as often), so a station drawing thousands of robots is not flooded
    assert drive[-1]["event"] == "arrived", drive
    drive = [line for line in drive if line["event"] in ("accepted", "progress")]
    times = [datetime.fromisoformat(line["at"]).timestamp() for line in drive]
    assert [line["event"] for line in drive].count("progress") >= 1, drive
    gaps = [later - earlier for earlier, later in itertools.pairwise(times)]
    assert min(gaps) >= 0.9, gaps


def test_the_whole_swarm_sent_across_the_floor_at_once_arrives_and_none_is_stuck(
    up: Up, aws_credentials: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given the 200 robots at 20 times real time, where the 10 simulated seconds a robot
    # may go without progress before it is stuck are half a second of a busy machine
    api = up.endpoints["api"]
    monkeypatch.setenv("AWS_ENDPOINT_URL_IOT", api)
    iot = boto3.client("iot")

    def count_by(field: str) -> dict[str, int]:
        answer = iot.get_buckets_aggregation(
            queryString="thingName:rover*",
            aggregationField=field,
            bucketsAggregationType={"termsAggregation": {"maxBuckets": 10}},
        )
        return {bucket["keyValue"]: bucket["count"] for bucket in answer["buckets"]}

    # When every one of them is sent to zone D at once
    turn = say(api, "Alexa, ask robot fleet to send all robots to zone d")
    assert turn["commands"], turn
    # Then every robot arrives there, and none was stuck on the way (a stuck robot stays
    # `stuck` where it stopped)
    assert eventually(lambda: count_by("shadow.reported.zone") == {"D": SIZE}, 90), (
        count_by("shadow.reported.zone"),
        count_by("shadow.reported.status"),
    )
    assert count_by("shadow.reported.status") == {"idle": SIZE}


@pytest.mark.parametrize(
    ("value", "error"),
    [
        ("0", "--swarm 0: give 1 to 4,000 robots"),
        ("-3", "--swarm -3: give 1 to 4,000 robots"),
        ("4001", "--swarm 4001: give 1 to 4,000 robots"),
    ],
)
def test_a_bad_swarm_size_is_one_line_and_starts_nothing(
    value: str, error: str, tmp_path: Path
) -> None:
    state = tmp_path / "state"
    result = subprocess.run(
        [*VAHR, "up", "--swarm", value, "--state-dir", str(state), "--api-port", "1"],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.startswith(f"vahr up: error: {error} (")
    assert result.stderr.count("\n") == 1
    assert not state.exists()
