"""The catch-all path: whatever fails, Alexa still gets valid speech."""

from __future__ import annotations

from typing import Any

import pytest
from skill_testkit import published, reprompt, speech

from skill.app import make_lambda_handler
from skill.config import SkillConfig
from skill.errors import GatewayError
from skill.iot_data import IotDataGateway, create_client
from tests.conftest import load_event

GATEWAY_SPEECH = "Sorry, I could not reach the robots just now. Please try again in a moment."


class BrokenGateway:
    """A data plane that is down: every call fails as the boto3 adapter would report it."""

    def publish(self, topic: str, payload: bytes) -> None:
        raise GatewayError(f"publish to {topic} failed: ServiceUnavailableException")

    def get_shadow(self, thing: str) -> bytes | None:
        raise GatewayError(f"reading the shadow of {thing} failed: ThrottlingException")

    def update_shadow(self, thing: str, payload: bytes) -> bytes:
        raise GatewayError(f"updating the shadow of {thing} failed: ThrottlingException")


@pytest.mark.parametrize(
    "event", ["alexa_navigate", "alexa_emergency_stop", "alexa_status", "alexa_weather"]
)
def test_gateway_error_still_yields_valid_speech(aws: None, event: str) -> None:
    skill = make_lambda_handler(SkillConfig(), gateway=BrokenGateway())
    response = skill(load_event(event), None)
    assert speech(response) == GATEWAY_SPEECH
    assert response["response"]["shouldEndSession"] is True


def test_gateway_error_inside_a_conversation_keeps_listening(aws: None) -> None:
    skill = make_lambda_handler(SkillConfig(), gateway=BrokenGateway())
    response = skill(load_event("alexa_navigate_in_conversation"), None)
    assert speech(response) == GATEWAY_SPEECH
    assert reprompt(response) == "What would you like the robots to do?"
    assert response["response"]["shouldEndSession"] is False


def test_unreachable_endpoint_is_spoken_as_a_gateway_error(aws: None) -> None:
    # Given the real boto3 adapter pointed at a port where nothing listens
    from vahr.plumbing.ports import free_port

    config = SkillConfig(data_endpoint=f"http://127.0.0.1:{free_port()}")
    skill = make_lambda_handler(config, gateway=IotDataGateway(create_client(config)))
    response = skill(load_event("alexa_navigate"), None)
    assert speech(response) == GATEWAY_SPEECH


def test_a_thing_unknown_to_iot_reads_as_not_reported(make_skill: Any, iot_data: Any) -> None:
    # Given placebot1's thing was deleted from IoT (its shadow reads answer 404)
    import boto3

    boto3.client("iot", region_name="us-east-1").delete_thing(thingName="placebot1")
    response = make_skill(ack_timeout_s=0.2)(load_event("alexa_status_robot"), None)
    # Then reading found no shadow: the robot has not reported
    assert speech(response) == "Placebot one has not reported yet."


def test_an_intent_without_a_handler_gets_the_safe_sentence(skill: Any, aws: None) -> None:
    response = skill(load_event("alexa_unknown_intent"), None)
    assert speech(response) == "Sorry, something went wrong on my side. Please try again."
    assert published() == []


def test_a_failure_that_cannot_be_recorded_is_still_answered(
    skill: Any, aws: None, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    # Given a request that fails and a trail whose record of it fails too
    def unrecordable(*_: object) -> None:
        raise AttributeError("'NoneType' object has no attribute 'value'")

    monkeypatch.setattr("skill.handlers.catch_all.record_failure", unrecordable)
    response = skill(load_event("alexa_unknown_intent"), None)
    # Then Alexa still gets the safe sentence, and the lost record is logged
    assert speech(response) == "Sorry, something went wrong on my side. Please try again."
    assert '"event": "trail_failed"' in caplog.text


def test_one_unreadable_shadow_does_not_hide_the_others(make_skill: Any, robots: Any) -> None:
    class HalfBroken(IotDataGateway):
        def get_shadow(self, thing: str) -> bytes | None:
            if thing == "placebot2":
                raise GatewayError("reading the shadow of placebot2 failed: ThrottlingException")
            return super().get_shadow(thing)

    skill = make_lambda_handler(SkillConfig(), gateway=HalfBroken(robots.iot_data))
    response = skill(load_event("alexa_status"), None)
    assert speech(response) == (
        "Placebot one is idle in the loading zone. I could not read the state of placebot two."
    )


def test_the_endpoint_variable_reaches_the_iot_data_client(
    aws: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given AWS_ENDPOINT_URL_IOT_DATA_PLANE pointing at a port where nothing listens
    from vahr.plumbing.ports import free_port

    url = f"http://127.0.0.1:{free_port()}"
    monkeypatch.setenv("AWS_ENDPOINT_URL_IOT_DATA_PLANE", url)
    # When the handler is built from the environment, as at cold start
    config = SkillConfig.from_env()
    skill = make_lambda_handler()
    # Then it talks to that endpoint (and not to moto, which would have answered)
    assert config.data_endpoint == url
    assert speech(skill(load_event("alexa_navigate"), None)) == GATEWAY_SPEECH
    assert published() == []
