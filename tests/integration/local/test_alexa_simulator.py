"""The Alexa simulator driving the real skill on the local data plane: sessions,
attributes across turns, slot elicitation answered with a bare value, and the commands a
turn published."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

import pytest

from vahr.errors import VahrError
from vahr.local.alexa_host import serve_alexa
from vahr.plumbing.client import call
from vahr.plumbing.mqtt import MqttClient
from vahr.protocol import topics
from vahr.protocol.station_topics import AssistantTurn, decode_turn

if TYPE_CHECKING:
    from vahr.assistant.simulator import AlexaSimulator
    from vahr.twin.stack import LocalStack


@pytest.fixture(scope="module")
def alexa(local_stack: LocalStack) -> AlexaSimulator:
    # No robots run here, so a short acknowledgment wait keeps the tests quick.
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("AWS_ACCESS_KEY_ID", "testing")
        patch.setenv("AWS_SECRET_ACCESS_KEY", "testing")
        patch.setenv("AWS_DEFAULT_REGION", "us-east-1")
        return serve_alexa(local_stack, ack_timeout_s=0.2)


def test_an_unknown_robot_is_asked_for_and_a_bare_answer_completes_it(
    alexa: AlexaSimulator,
) -> None:
    first = alexa.say("Alexa, ask robot fleet to send robot nine to zone b")
    assert first.intent == "NavigateIntent"
    assert first.slots["robot"] == {"value": "robot nine", "id": None}
    assert "Which robot" in first.speech
    assert first.session_open and first.commands == []
    # When the person answers with the robot's name alone
    second = alexa.say("robot two")
    # Then the skill gets the same intent with both slots and publishes the command
    assert second.intent == "NavigateIntent"
    assert second.slots["robot"] == {"value": "robot two", "id": "placebot2"}
    assert second.slots["zone"]["id"] == "B"
    assert len(second.commands) == 1
    alexa.end_session()


def test_launch_then_help_then_stop(alexa: AlexaSimulator) -> None:
    launch = alexa.say("Alexa, open robot fleet")
    assert launch.request_type == "LaunchRequest"
    assert launch.session_open
    helped = alexa.say("help")
    assert helped.intent == "AMAZON.HelpIntent"
    assert helped.session_open
    stopped = alexa.say("stop")
    assert stopped.intent == "AMAZON.StopIntent"
    assert not stopped.session_open


def test_an_unmatched_utterance_goes_to_the_fallback_intent(alexa: AlexaSimulator) -> None:
    turn = alexa.say("Alexa, ask robot fleet to bake a cake")
    assert turn.intent == "AMAZON.FallbackIntent"
    assert turn.speech
    alexa.end_session()


def test_a_paraphrase_the_samples_lack_publishes_the_command(alexa: AlexaSimulator) -> None:
    turn = alexa.say("Alexa, ask robot fleet: would you send placebot one over to zone c?")
    assert turn.intent == "NavigateIntent"
    assert {name: slot["id"] for name, slot in turn.slots.items()} == {
        "robot": "placebot1",
        "zone": "C",
    }
    assert len(turn.commands) == 1


def test_a_missing_zone_is_asked_for_and_a_wordy_answer_completes_it(
    alexa: AlexaSimulator,
) -> None:
    # Given a request that names the robot only
    first = alexa.say("Alexa, ask robot fleet to send robot one")
    assert first.commands == [] and first.session_open
    assert "zone" in first.speech.lower()
    # When the answer wraps the zone in other words
    second = alexa.say("um over to zone b please")
    # Then the pending request is completed with it and published once
    assert second.intent == "NavigateIntent"
    assert second.slots["robot"]["id"] == "placebot1"
    assert second.slots["zone"]["id"] == "B"
    assert len(second.commands) == 1
    alexa.end_session()


def test_a_new_request_during_a_question_is_taken_as_itself(alexa: AlexaSimulator) -> None:
    first = alexa.say("Alexa, ask robot fleet to send robot nine to zone b")
    assert "Which robot" in first.speech
    # When the person asks something else instead of answering
    second = alexa.say("where are the robots")
    # Then that question is answered and nothing is sent
    assert second.intent == "StatusIntent"
    assert second.commands == []
    alexa.end_session()


@pytest.mark.parametrize(
    "utterance",
    [
        "send robot one to zone a or zone b",  # two zones, neither the only destination
        "send placebot three to the loading zone",  # a robot the fleet does not have
    ],
)
def test_an_unclear_target_is_asked_for_and_nothing_moves(
    alexa: AlexaSimulator, utterance: str
) -> None:
    turn = alexa.say(f"Alexa, ask robot fleet to {utterance}")
    assert turn.intent == "NavigateIntent"
    assert turn.commands == []
    assert turn.session_open and "?" in turn.speech
    alexa.end_session()


def test_a_name_too_far_from_any_robot_s_moves_nothing(alexa: AlexaSimulator) -> None:
    # "plays robot" is no robot of the fleet; whether it is asked about or not understood
    # (it reads as near "send a robot" too, the fleet's dispatch), no robot moves
    turn = alexa.say("Alexa, ask robot fleet to move plays robot to zone c")
    assert turn.intent in ("NavigateIntent", "AMAZON.FallbackIntent")
    assert turn.commands == []
    assert "?" in turn.speech or "I sent nothing to the robots" in turn.speech
    alexa.end_session()


def test_out_of_domain_requests_send_nothing(alexa: AlexaSimulator) -> None:
    for utterance in ("what's the capital of peru", "play some jazz please"):
        turn = alexa.say(f"Alexa, ask robot fleet {utterance}")
        assert turn.intent == "AMAZON.FallbackIntent"
        assert turn.commands == []
        alexa.end_session()


def test_every_turn_is_published_for_the_station(
    local_stack: LocalStack, alexa: AlexaSimulator
) -> None:
    seen: list[AssistantTurn] = []
    arrived = threading.Event()

    def on_turn(topic: str, payload: bytes) -> None:
        seen.append(decode_turn(payload))
        arrived.set()

    with MqttClient(local_stack.service_endpoint()) as watcher:
        watcher.subscribe(topics.ASSISTANT_TURNS, on_turn)
        # When the station's weather button asks the assistant
        alexa.say("Alexa, ask robot fleet what is the weather", origin="station-weather")
        assert arrived.wait(10)
    # Then the turn is on the broker, saying who spoke and what was understood
    (turn,) = seen
    assert (turn.origin, turn.intent) == ("station-weather", "WeatherIntent")
    assert turn.utterance == "Alexa, ask robot fleet what is the weather" and turn.speech


def test_say_names_who_spoke_and_refuses_a_bad_name(
    local_stack: LocalStack, alexa: AlexaSimulator
) -> None:
    heard = {"transcript": "where is robot one", "confidence": 0.9, "accepted": True}
    turn = call(local_stack.api_url, "POST", "/vahr/say",
                {"utterance": "where is robot one", "origin": "station-voice", "heard": heard})  # fmt: skip
    assert turn["origin"] == "station-voice" and turn["heard"]["confidence"] == 0.9
    with pytest.raises(VahrError, match="answered 400: origin: must be a short lower-case word"):
        call(local_stack.api_url, "POST", "/vahr/say", {"utterance": "hi", "origin": "Not Me!"})
    with pytest.raises(VahrError, match="answered 400: heard"):
        call(
            local_stack.api_url,
            "POST",
            "/vahr/say",
            {"utterance": "hi", "heard": {"confidence": "high"}},
        )


def test_an_exit_word_of_the_locale_ends_the_open_session(alexa: AlexaSimulator) -> None:
    opened = alexa.say("Alexa, open robot fleet")
    assert opened.session_open
    # "good bye" is one of en-US's exits (its understanding.yaml), said as two words
    turn = alexa.say("Good bye!")
    assert turn.request_type == "SessionEndedRequest"
    assert not alexa.session_open and turn.commands == []
