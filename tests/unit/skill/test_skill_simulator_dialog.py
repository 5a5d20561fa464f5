"""The Alexa simulator and the real skill (moto) in one conversation: the yes to
Dialog.ConfirmSlot comes back CONFIRMED, silence moves nothing, an Understanding handed in
(as push-to-talk hands in its N best) with alternatives is asked about, and a correction
reaches the last command only within the window after its session ended."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import published

from vahr.assistant.nlu import InteractionModel, SlotValue, Understanding
from vahr.assistant.simulator import CONFIRM_SLOT, SILENCE, AlexaSimulator
from vahr.protocol.conversation import CORRECTION_WINDOW_S

if TYPE_CHECKING:
    from collections.abc import Callable


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


class Clock:
    """The simulator's monotonic clock, moved by the test."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def clock() -> Clock:
    return Clock()


@pytest.fixture
def alexa(model: InteractionModel, skill: Callable[..., Any], clock: Clock) -> AlexaSimulator:
    return AlexaSimulator(model, skill, clock=clock)


def commands() -> list[tuple[str, str, dict[str, Any]]]:
    sent = [(topic, json.loads(payload)) for topic, payload in published()]
    return [(topic, body["action"], body["params"]) for topic, body in sent]


def test_yes_to_a_confirmed_slot_moves_the_other_robot(alexa: AlexaSimulator, robots: Any) -> None:
    alexa.say("Alexa, open robot fleet")
    alexa.say("send placebot one to zone c")
    asked = alexa.say("not that robot")
    assert asked.speech == "Placebot two instead?"
    assert alexa.pending is not None and alexa.pending.directive == CONFIRM_SLOT
    done = alexa.say("yes")
    assert done.intent == "CorrectionIntent"
    assert commands()[-2:] == [
        ("vahr/robots/placebot1/cmd", "stop", {}),
        ("vahr/robots/placebot2/cmd", "navigate", {"zone": "C"}),
    ]
    assert "Placebot two is on its way to zone C." in done.speech


def test_silence_moves_nothing_and_says_so(alexa: AlexaSimulator, aws: None) -> None:
    turn = alexa.say("   ")
    assert (turn.speech, turn.commands) == (SILENCE, [])
    assert published() == []


def test_an_understanding_with_alternatives_is_asked_about(
    alexa: AlexaSimulator, robots: Any
) -> None:
    # What push-to-talk hands in when its hearings disagree on the zone
    heard = Understanding(
        "NavigateIntent",
        {
            "robot": SlotValue("robot", "ROBOT", "placebot one", "placebot1", "placebot one"),
            "zone": SlotValue("zone", "ZONE", "zone b", "B", "zone b", 80.0, (("D", "zone d"),)),
        },
        ("robot", "zone"),
    )
    asked = alexa.say("send placebot one to zone b", understanding=heard)
    assert asked.speech == "Zone B or zone D?"
    assert published() == []
    done = alexa.say("zone d")
    assert commands() == [("vahr/robots/placebot1/cmd", "navigate", {"zone": "D"})]
    assert done.speech.startswith("Placebot one is on its way to zone D.")


def test_a_correction_reaches_a_one_shot_command_only_within_the_window(
    alexa: AlexaSimulator, robots: Any, clock: Clock
) -> None:
    sent = alexa.say("Alexa, ask robot fleet to send placebot one to zone c")
    assert not sent.session_open
    clock.now += CORRECTION_WINDOW_S - 1
    corrected = alexa.say("Alexa, ask robot fleet no, zone b")
    assert corrected.speech.startswith("Okay, not zone C. Placebot one is on its way to zone B.")
    clock.now += CORRECTION_WINDOW_S + 1
    late = alexa.say("Alexa, ask robot fleet no, zone a")
    assert late.speech == "There is no command of mine to correct, so I changed nothing."
    assert [action for _, action, _ in commands()] == ["navigate", "navigate"]


def test_the_station_corrects_by_typing_what_it_said_by_voice(
    alexa: AlexaSimulator, robots: Any, clock: Clock
) -> None:
    # The operator at the station says a command into push-to-talk, then types its
    # correction: one person at one station
    alexa.say("Alexa, ask robot fleet to send placebot one to zone c", origin="station-voice")
    clock.now += 5
    corrected = alexa.say("Alexa, ask robot fleet no, zone b", origin="station")
    assert corrected.speech.startswith("Okay, not zone C. Placebot one is on its way to zone B.")
    # Someone else (the command line) has nothing of theirs to correct
    clock.now += 5
    other = alexa.say("Alexa, ask robot fleet cancel that", origin="say")
    assert other.speech.startswith("There is no command of mine to cancel, so I changed nothing.")
    assert [action for _, action, _ in commands()] == ["navigate", "navigate"]
