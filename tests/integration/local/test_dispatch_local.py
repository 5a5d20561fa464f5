"""Fleet dispatch on `vahr up --fleet tests/fleets/six_robots.yaml`, spoken through `vahr say`.

Each spoken form reaches the real skill through the Alexa simulator, the skill's TaskDesk
reaches the local dispatcher over HTTP, the dispatcher publishes on the real broker and
the simulated robots drive; the tests read which robot moved where from the robots'
shadows (`GET /vahr/status`). The queue test stops `vahr up` while every robot holds a
task and one more waits in line, and starts it again on the same state directory.
"""

from __future__ import annotations

import json
import subprocess
import time
import urllib.request
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.fleets import SIX_ROBOTS
from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, start_up, stop_up

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

BIRDS = ("kestrel", "heron", "osprey", "plover", "curlew", "dunlin")
# The first utterance waits for the simulator's classifier, trained at start.
FIRST_SAY_TIMEOUT_S = 240.0


def get(api: str, path: str) -> dict[str, Any]:
    with urllib.request.urlopen(api + path, timeout=10) as response:
        body: dict[str, Any] = json.loads(response.read())
        return body


def reported(api: str) -> dict[str, dict[str, Any]]:
    return {thing: state or {} for thing, state in get(api, "/vahr/status")["robots"].items()}


def wait_for(check: Callable[[], Any], timeout_s: float, what: str) -> Any:
    deadline = time.monotonic() + timeout_s
    while True:
        found = check()
        if found:
            return found
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.2)


def say(api: str, utterance: str, timeout_s: float = 60.0) -> dict[str, Any]:
    """`vahr say --json`; the first call of a stack may wait for the classifier."""
    done = subprocess.run(
        [*VAHR, "say", "--json", "--api", api, utterance],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=timeout_s,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    turn: dict[str, Any] = json.loads(done.stdout)
    return turn


def online(api: str) -> bool:
    states = reported(api)
    return all(states.get(thing, {}).get("connected") for thing in BIRDS)


def settled(api: str, things: tuple[str, ...] | list[str], zone: str) -> bool:
    states = reported(api)
    return all(
        states[thing].get("zone") == zone and states[thing].get("status") == "idle"
        for thing in things
    )


def endpoint(up: Up) -> str:
    """The data plane's URL, from the first line `vahr up --json` prints: robots that act
    while it starts (after a restart, at once) print their events after it."""
    assert "api" in up.endpoints, f"the first line is not the endpoints: {up.endpoints}"
    return str(up.endpoints["api"])


def warm(up: Up) -> str:
    api = endpoint(up)
    wait_for(lambda: online(api), 60, "six robots online")
    deadline = time.monotonic() + FIRST_SAY_TIMEOUT_S
    while True:  # `vahr say` gives up on a simulator still training; ask again
        try:
            say(api, "what is queued", timeout_s=FIRST_SAY_TIMEOUT_S)
            return api
        except AssertionError:
            if time.monotonic() > deadline:
                raise


@pytest.fixture(scope="module")
def fast_bakery(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    state = tmp_path_factory.mktemp("bakery")
    up = start_up(state, "--fleet", str(SIX_ROBOTS), "--sim-speed-factor", "30")
    try:
        yield warm(up)
    finally:
        stop_up(up.process)


def test_a_delivery_naming_no_robot_goes_to_the_robot_nearest_the_mill(fast_bakery: str) -> None:
    turn = say(fast_bakery, "deliver a package to the oven")
    # osprey starts 2.2 m from the mill: the shortest way to the mill and on to the oven.
    assert turn["speech"] == "Osprey is on its way to pick up a package for the oven."
    wait_for(lambda: settled(fast_bakery, ["osprey"], "OVEN"), 60, "osprey in the oven")
    assert all(reported(fast_bakery)[bird].get("zone") != "OVEN" for bird in BIRDS[:2])


def test_counted_grouped_zoned_and_idle_robots_go_where_they_are_sent(fast_bakery: str) -> None:
    turn = say(fast_bakery, "send two robots to the shop")
    assert turn["intent"] == "FleetNavigateIntent"
    shop = [bird for bird in BIRDS if bird in turn["speech"].lower()]
    assert len(shop) == 2, turn["speech"]
    wait_for(lambda: settled(fast_bakery, shop, "SHOP"), 60, f"{shop} in the shop")

    turn = say(fast_bakery, "send the waders to the pantry")
    assert turn["speech"] == "Plover, curlew and dunlin are on their way to the pantry."
    wait_for(lambda: settled(fast_bakery, ["plover", "curlew", "dunlin"], "PANTRY"), 60, "waders")

    in_shop = sorted(t for t, s in reported(fast_bakery).items() if s.get("zone") == "SHOP")
    turn = say(fast_bakery, "send the robots in the shop to the mill")
    assert turn["intent"] == "ZoneRobotsIntent"
    if in_shop:
        wait_for(lambda: settled(fast_bakery, in_shop, "LOADING"), 60, "the shop's robots")
    else:
        assert turn["speech"] == "No free robot is in the shop, so I sent none."

    turn = say(fast_bakery, "send every idle robot to the oven")
    assert turn["intent"] == "IdleRobotsIntent"
    wait_for(lambda: settled(fast_bakery, BIRDS, "OVEN"), 60, "every robot in the oven")


def test_nine_robots_of_six_is_said_and_nothing_moves(fast_bakery: str) -> None:
    turn = say(fast_bakery, "send nine robots to the shop")
    assert turn["speech"] == "The fleet has 6 robots, so I cannot send 9."
    assert get(fast_bakery, "/vahr/tasks")["tasks"] == [] or all(
        task["zone"] != "SHOP" or task["status"] != "queued"
        for task in get(fast_bakery, "/vahr/tasks")["tasks"]
    )


def test_the_queue_survives_a_restart_and_starts_when_a_robot_frees(tmp_path: Path) -> None:
    state = tmp_path / "bakery"
    state.mkdir()
    # Real time: every robot takes tens of seconds to cross the bakery.
    up = start_up(state, "--fleet", str(SIX_ROBOTS), "--sim-speed-factor", "1")
    try:
        api = warm(up)
        sent = say(api, "send every idle robot to the pantry")
        assert sent["intent"] == "IdleRobotsIntent"
        turn = say(api, "deliver a package to the oven")
        assert turn["speech"] == "All robots are busy; the delivery to the oven is first in line."
        queued = [task for task in get(api, "/vahr/tasks")["tasks"] if task["status"] == "queued"]
        assert [task["zone"] for task in queued] == ["OVEN"]
        held = [task for task in get(api, "/vahr/tasks")["tasks"] if task["status"] == "assigned"]
        assert sorted(task["thing"] for task in held) == sorted(BIRDS)
    finally:
        # Stopped with six tasks assigned and one queued: a restart mid-assignment.
        stop_up(up.process)
    up = start_up(state, "--fleet", str(SIX_ROBOTS), "--sim-speed-factor", "30")
    try:
        api = endpoint(up)

        # The delivery survived the restart: still listed, or (robots at 30 times real time
        # may free, take it and finish before the first look) already some robot's command.
        def survived() -> bool:
            listed = [t for t in get(api, "/vahr/tasks")["tasks"] if t["id"] == queued[0]["id"]]
            assert all(task["zone"] == "OVEN" for task in listed)
            taken = any(
                (state.get("last_command") or {}).get("id") == queued[0]["id"]
                for state in reported(api).values()
            )
            return bool(listed) or taken

        wait_for(survived, 30, "the queued delivery after the restart")
        wait_for(lambda: online(api), 60, "six robots online")
        # The robots report what became of their interrupted trips, are free again, and
        # the first one free takes the delivery: it ends in the oven.
        taker = wait_for(
            lambda: next(
                (
                    thing
                    for thing, state in reported(api).items()
                    if (state.get("last_command") or {}).get("id") == queued[0]["id"]
                ),
                None,
            ),
            90,
            "a robot taking the queued delivery",
        )
        wait_for(lambda: settled(api, [taker], "OVEN"), 90, f"{taker} in the oven")
        tasks = get(api, "/vahr/tasks")["tasks"]
        assert all(task["status"] != "queued" for task in tasks)
        assert len({task["thing"] for task in tasks if task["status"] == "assigned"}) == len(
            [task for task in tasks if task["status"] == "assigned"]
        )
    finally:
        stop_up(up.process)
