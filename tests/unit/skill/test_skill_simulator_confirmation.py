"""The simulated Echo confirms a reading its NLU is unsure of before the skill hears of it,
as Alexa says an intent's confirmation prompt under auto-delegation: the yes reaches the
real skill (moto) as the intent CONFIRMED and is carried out, the no as DENIED and nothing
is sent, and anything else is a request of its own."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import published

from vahr.assistant.nlu import InteractionModel, SlotValue, Understanding
from vahr.assistant.simulator import CONFIRM_INTENT, AlexaSimulator

if TYPE_CHECKING:
    from collections.abc import Callable

# Two robots and two zones with no word for who goes first or where: the tagger's best
# reading (placebot one to C, then placebot two to D) is a guess.
UNSURE = "Alexa, ask robot fleet to placebot one placebot two zone c zone d deliver"
PROMPT = "Placebot one to zone c, then placebot two to zone d: is that right?"


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


@pytest.fixture
def alexa(model: InteractionModel, skill: Callable[..., Any]) -> AlexaSimulator:
    requests: list[dict[str, Any]] = []

    def heard(event: dict[str, Any], context: Any) -> dict[str, Any]:
        requests.append(event["request"])
        return skill(event, context)

    simulator = AlexaSimulator(model, heard)
    simulator.requests = requests  # type: ignore[attr-defined]
    return simulator


def commands() -> list[tuple[str, str, dict[str, Any]]]:
    sent = [(topic, json.loads(payload)) for topic, payload in published()]
    return [(topic, body["action"], body["params"]) for topic, body in sent]


def test_an_unsure_reading_is_confirmed_before_anything_is_sent(
    alexa: AlexaSimulator, robots: Any
) -> None:
    asked = alexa.say(UNSURE)
    assert asked.speech == PROMPT
    assert asked.request_type == CONFIRM_INTENT and asked.session_open
    assert alexa.pending is not None and alexa.pending.directive == CONFIRM_INTENT
    # The skill has not been called: Alexa asks its confirmation prompt itself.
    assert alexa.requests == []  # type: ignore[attr-defined]
    assert published() == []


def test_yes_carries_the_reading_out(alexa: AlexaSimulator, robots: Any) -> None:
    alexa.say(UNSURE)
    done = alexa.say("yes")
    [request] = alexa.requests  # type: ignore[attr-defined]
    assert request["type"] == "IntentRequest"
    assert request["intent"]["name"] == "SequentialDeliveryIntent"
    assert request["intent"]["confirmationStatus"] == "CONFIRMED"
    slots = {name: slot["value"] for name, slot in request["intent"]["slots"].items()}
    assert slots == {
        "firstRobot": "placebot one",
        "firstZone": "zone c",
        "secondRobot": "placebot two",
        "secondZone": "zone d",
    }
    sent = commands()
    assert [(topic, action) for topic, action, _ in sent] == [
        ("vahr/robots/placebot1/cmd", "sequential_delivery"),
        ("vahr/robots/placebot2/cmd", "sequential_delivery"),
    ]
    assert sent[0][2]["zone"] == "C" and not sent[0][2].get("after")
    assert sent[1][2] == {"zone": "D", "after": "placebot1"}
    assert done.speech.startswith(
        "Placebot one will deliver to zone C, then placebot two will deliver to zone D."
    )


def test_no_sends_nothing_and_says_so(alexa: AlexaSimulator, robots: Any) -> None:
    alexa.say(UNSURE)
    denied = alexa.say("no")
    [request] = alexa.requests  # type: ignore[attr-defined]
    assert request["intent"]["confirmationStatus"] == "DENIED"
    assert denied.speech.startswith("Okay, I sent nothing. Please say it again.")
    assert denied.session_open
    assert published() == []
    # Said again, clearly, it is carried out at once.
    again = alexa.say("placebot one delivers to zone c, then placebot two delivers to zone d")
    assert again.request_type == "IntentRequest"
    assert [action for _, action, _ in commands()] == ["sequential_delivery"] * 2


def test_another_request_instead_of_an_answer_is_a_request_of_its_own(
    alexa: AlexaSimulator, robots: Any
) -> None:
    alexa.say(UNSURE)
    instead = alexa.say("send placebot two to zone a")
    assert instead.intent == "NavigateIntent"
    assert commands() == [("vahr/robots/placebot2/cmd", "navigate", {"zone": "A"})]


def test_a_german_echo_says_the_reading_back_and_hears_ja(
    model: InteractionModel, skill: Callable[..., Any], robots: Any
) -> None:
    # What push-to-talk hands in when the roles of its best hearing are a guess
    unsure = Understanding(
        "NavigateIntent",
        {
            "robot": SlotValue("robot", "ROBOT", "placebot eins", "placebot1", "placebot eins"),
            "zone": SlotValue("zone", "ZONE", "zone b", "B", "zone b"),
        },
        ("robot", "zone"),
        roles_confidence=0.3,
    )
    alexa = AlexaSimulator(model, skill, locale="de-DE")
    asked = alexa.say("placebot eins zone b", understanding=unsure)
    assert asked.speech == "Placebot eins nach zone b: ist das richtig?"
    assert published() == []
    done = alexa.say("ja")
    assert commands() == [("vahr/robots/placebot1/cmd", "navigate", {"zone": "B"})]
    assert done.speech.startswith("Placebot eins")
