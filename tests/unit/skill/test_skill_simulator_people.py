"""People through the simulated Echo and the real skill (moto): each Alexa account has a
session of its own, so one person's open question is not answered by another's yes; on one
account, a recognised voice's yes to another person's question is refused by the skill;
the skill hears who spoke and through what; the confirmation asked and answered in German.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import published

from vahr.assistant.localized import load_model
from vahr.assistant.nlu import InteractionModel
from vahr.assistant.simulator import AlexaSimulator
from vahr.protocol import topics
from vahr.protocol.audit import RequestSource

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

SUSAN = "amzn1.ask.account.SUPERVISORSUSAN"
OTTO = "amzn1.ask.account.OPERATOROTTO"
OTTO_VOICE = "amzn1.ask.person.OTTOSVOICE"
USERS = f"""
users:
  - {{id: {SUSAN}, name: Susan, role: supervisor}}
  - {{id: {OTTO}, name: Otto, role: operator}}
  - {{id: {OTTO_VOICE}, name: Otto, role: operator}}
"""


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


@pytest.fixture
def skill(make_skill: Callable[..., Any], tmp_path: Path) -> Callable[..., Any]:
    users = tmp_path / "users.yaml"
    users.write_text(USERS, encoding="utf-8")
    handler: Callable[..., Any] = make_skill(users_file=str(users), ack_timeout_s=1.0)
    return handler


@pytest.fixture
def heard() -> list[tuple[dict[str, Any], Any]]:
    """Every envelope the skill was called with, and the context beside it."""
    return []


@pytest.fixture
def alexa(
    model: InteractionModel,
    skill: Callable[..., Any],
    heard: list[tuple[dict[str, Any], Any]],
) -> AlexaSimulator:
    def handler(event: dict[str, Any], context: Any) -> dict[str, Any]:
        heard.append((event, context))
        answer: dict[str, Any] = skill(event, context)
        return answer

    return AlexaSimulator(model, handler)


def fleet_commands() -> list[dict[str, Any]]:
    return [json.loads(p) for topic, p in published() if topic == topics.FLEET_CMD]


def test_another_accounts_yes_is_in_its_own_session_and_moves_nothing(
    alexa: AlexaSimulator, robots: Any
) -> None:
    asked = alexa.say("send all robots to zone a", user=SUSAN)
    assert asked.speech == "Send all robots to zone A, is that right?"
    # Otto's yes, on his own account, answers no question of his
    alexa.say("yes", user=OTTO)
    assert fleet_commands() == []
    assert alexa.pending_for(SUSAN) is not None and alexa.pending_for(OTTO) is None
    # Susan's yes carries out hers
    done = alexa.say("yes", user=SUSAN)
    assert done.speech == "Both robots are on their way to zone A."
    assert [command["params"] for command in fleet_commands()] == [{"zone": "A"}]


def test_on_one_echo_another_voices_yes_is_refused(alexa: AlexaSimulator, robots: Any) -> None:
    # Susan asks on the lab's Echo (her account); Alexa recognises Otto's voice in the yes
    alexa.say("send all robots to zone a", user=SUSAN)
    answer = alexa.say("yes", user=SUSAN, person=OTTO_VOICE)
    assert answer.speech == "Only the person who asked for that can confirm it, so I sent nothing."
    assert fleet_commands() == []


def test_the_skill_hears_who_spoke_and_through_what(
    alexa: AlexaSimulator, heard: list[tuple[dict[str, Any], Any]], robots: Any
) -> None:
    alexa.say("where are the robots", user=OTTO, person=OTTO_VOICE, origin="station-voice")
    [(event, context)] = heard
    system = event["context"]["System"]
    assert system["user"]["userId"] == OTTO
    assert system["person"]["personId"] == OTTO_VOICE
    assert event["session"]["user"]["userId"] == OTTO
    assert context == RequestSource(channel="station-voice", words="where are the robots")


def test_the_confirmation_is_asked_and_answered_in_german(
    skill: Callable[..., Any], robots: Any
) -> None:
    alexa = AlexaSimulator(load_model("de-DE"), skill, locale="de-DE")
    asked = alexa.say("schicke alle roboter in zone a", user=SUSAN)
    assert asked.speech == "Alle Roboter nach Zone A schicken: ist das richtig?"
    assert fleet_commands() == []
    alexa.say("ja", user=SUSAN)
    assert [command["params"] for command in fleet_commands()] == [{"zone": "A"}]
