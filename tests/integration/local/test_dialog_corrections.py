"""The issue's three cases end to end, as a person speaks them through `vahr say` to `vahr
up` with robots driving in the simulator: a whole command answering "which robot?" is acted
on with its own zone, "no, zone b" turns the robot around and "cancel that" stops that
robot only, and a zone said two ways is asked about instead of acted on. Bad input moves
nothing and the reply says so."""

from __future__ import annotations

import queue
import time
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.vahr_up import Up, start_up, stop_up
from tests.support.vahr_up import say as say_to
from vahr.plumbing.client import call
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from collections.abc import Iterator


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    # Slow enough that a robot is still on its way when the correction comes.
    running = start_up(
        tmp_path_factory.mktemp("dialog"),
        "--station-port",
        str(free_port()),
        "--sim-speed-factor",
        "4",
    )
    try:
        yield running
    finally:
        stop_up(running.process)


def say(up: Up, utterance: str) -> dict[str, Any]:
    return say_to(up.endpoints["api"], utterance)


def events_for(up: Up, command_id: str, settle_s: float) -> list[dict[str, Any]]:
    """Every event `vahr up` printed for `command_id` within `settle_s`."""
    seen: list[dict[str, Any]] = []
    deadline = time.monotonic() + settle_s
    while (left := deadline - time.monotonic()) > 0:
        try:
            event = up.lines.get(timeout=left)
        except queue.Empty:
            break
        if event.get("command_id") == command_id:
            seen.append(event)
    return seen


def test_a_whole_command_answering_which_robot_is_acted_on_with_its_own_zone(up: Up) -> None:
    # Given the skill asked which robot to move to zone D, for the issue's own sentence
    asked = say(up, "Alexa, ask robot fleet to move the robot over to zone d")
    assert asked["intent"] == "NavigateIntent"
    assert asked["speech"].startswith("Which robot")
    assert asked["session_open"] and asked["commands"] == []
    # When the answer is a whole command with another zone
    turn = say(up, "robot two please go to zone a")
    # Then placebot two goes to zone A, not D
    assert turn["intent"] == "NavigateIntent"
    assert {name: slot["id"] for name, slot in turn["slots"].items()} == {
        "robot": "placebot2",
        "zone": "A",
    }
    assert turn["speech"].startswith("Placebot two is on its way to zone A.")
    [command] = turn["commands"]
    arrived = up.wait_event(command, "arrived", timeout_s=60)
    assert (arrived["event"], arrived["thing"], arrived["zone"]) == ("arrived", "placebot2", "A")


def test_no_zone_b_turns_the_robot_and_cancel_that_stops_only_it(up: Up) -> None:
    sent = say(up, "Alexa, ask robot fleet to send placebot one to zone c")
    assert sent["speech"].startswith("Placebot one is on its way to zone C.")
    assert not sent["session_open"]
    # The session has ended; the correction comes within the window all the same.
    corrected = say(up, "no, zone b")
    assert corrected["intent"] == "CorrectionIntent"
    assert corrected["speech"].startswith("Okay, not zone C. Placebot one is on its way to zone B.")
    [redirect] = corrected["commands"]
    assert up.wait_event(redirect, "accepted", timeout_s=20)["thing"] == "placebot1"
    undone = say(up, "cancel that")
    assert undone["intent"] == "UndoIntent"
    assert undone["speech"].startswith("Okay, I cancelled that. Placebot one has stopped.")
    [stop] = undone["commands"]
    events = events_for(up, stop, settle_s=3.0)
    # Only placebot one got the stop; placebot two, which was not named, carries on.
    assert {event["thing"] for event in events} == {"placebot1"}
    assert "stopped" in {event["event"] for event in events}


def test_a_zone_said_two_ways_is_asked_about_then_acted_on(up: Up) -> None:
    asked = say(up, "Alexa, ask robot fleet to send placebot one to zone b or zone d")
    assert asked["speech"].startswith("Zone B or zone D?")
    assert asked["commands"] == []
    turn = say(up, "zone b")
    assert turn["speech"].startswith("Placebot one is on its way to zone B.")
    assert len(turn["commands"]) == 1


def test_a_correction_with_nothing_to_correct_says_so(up: Up) -> None:
    # A speaker who has sent nothing (an origin of its own)
    turn = call(
        up.endpoints["api"], "POST", "/vahr/say", {"utterance": "no, zone b", "origin": "newcomer"}
    )
    assert turn["speech"] == "There is no command of mine to correct, so I changed nothing."
    assert turn["commands"] == []


def test_a_long_ramble_moves_nothing_and_says_so(up: Up) -> None:
    ramble = " ".join(
        ["so yesterday I was thinking about placebot one and zone b and how the robots"]
        + ["move around the warehouse and whether we should send them somewhere"] * 5
    )
    turn = say(up, f"Alexa, ask robot fleet {ramble}")
    assert turn["intent"] == "AMAZON.FallbackIntent"
    assert "I sent nothing to the robots." in turn["speech"]
    assert turn["commands"] == []
