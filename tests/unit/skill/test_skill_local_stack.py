"""The same skill on one machine: the local stack's data plane in place of AWS IoT Core.

The local stack (mosquitto, shadow service, data-plane HTTP API) runs for real; robots
are paho clients on the plaintext listener that answer each command with a shadow update
over MQTT, as robot-agent does. The skill talks to the data plane through boto3's iot-data
client, exactly as it talks to AWS.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

import paho.mqtt.client as mqtt
import pytest
from skill_testkit import speech

from skill.app import make_lambda_handler
from skill.config import SkillConfig
from tests.conftest import load_event
from vahr.plumbing.ports import free_port
from vahr.protocol import (
    LastCommand,
    Reported,
    decode_command,
    experiment_state_from_payload,
    topics,
)
from vahr.twin.stack import LocalStack, StackConfig

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.domain import Fleet


@pytest.fixture
def stack(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[LocalStack]:
    # boto3 signs every request; the local data plane accepts any credentials.
    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "local")
    monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "local")
    config = StackConfig(
        state_dir=tmp_path, mqtts_port=free_port(), mqtt_port=free_port(), api_port=free_port()
    )
    with LocalStack(config) as running:
        yield running


@pytest.fixture
def mqtt_robots(stack: LocalStack, fleet: Fleet) -> Iterator[list[str]]:
    """Robots that acknowledge every command through their shadows over MQTT."""
    received: list[str] = []
    subscribed = threading.Event()
    client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id="robots")

    def on_connect(client: mqtt.Client, *_: Any) -> None:
        client.subscribe([(topics.FLEET_CMD, 1), ("vahr/robots/+/cmd", 1)])

    def on_subscribe(*_: Any) -> None:
        subscribed.set()

    def on_message(client: mqtt.Client, _: Any, message: mqtt.MQTTMessage) -> None:
        command = decode_command(message.payload, fleet)
        received.append(message.topic)
        parsed = topics.parse_robot_topic(message.topic)
        things = fleet.robot_things if message.topic == topics.FLEET_CMD else (parsed[0],)  # type: ignore[index]
        for thing in things:
            state = Reported(
                status="navigating",
                destination=getattr(command.params, "zone", None),
                task=command.action,
                connected=True,
                last_command=LastCommand(command.id, command.action, "accepted"),
            )
            client.publish(topics.shadow(thing, "update"), state.to_payload(), qos=1)

    client.on_connect = on_connect
    client.on_subscribe = on_subscribe
    client.on_message = on_message
    assert stack.config.mqtt_port is not None
    client.connect("127.0.0.1", stack.config.mqtt_port)
    client.loop_start()
    try:
        assert subscribed.wait(5), "the robots did not subscribe"
        yield received
    finally:
        client.disconnect()
        client.loop_stop()


def test_commands_status_and_weather_through_the_local_data_plane(
    stack: LocalStack, mqtt_robots: list[str]
) -> None:
    # Given the skill pointed at the local data plane, as `vahr up` points it
    skill = make_lambda_handler(SkillConfig(data_endpoint=stack.api_url, ack_timeout_s=2.5))
    # When the person sends one robot, then the fleet, then asks what they are doing
    one = speech(skill(load_event("alexa_navigate"), None))
    everyone = speech(skill(load_event("alexa_navigate_fleet"), None))
    status = speech(skill(load_event("alexa_status"), None))
    weather = [speech(skill(load_event("alexa_weather"), None)) for _ in range(2)]
    # Then each command reached the robots over MQTT and their acknowledgments came back
    assert mqtt_robots == ["vahr/robots/placebot1/cmd", "vahr/fleet/cmd"]
    assert one == "Placebot one is on its way to zone A."
    assert everyone == "Both robots are on their way to the loading zone."
    assert status == (
        "Placebot one is on its way to the loading zone. "
        "Placebot two is on its way to the loading zone."
    )
    # ...and the weather drawn once is stored in the local experiment shadow
    import boto3

    data_plane = boto3.client("iot-data", endpoint_url=stack.api_url, region_name="us-east-1")
    payload = data_plane.get_thing_shadow(thingName="vahr-experiment")["payload"].read()
    stored = experiment_state_from_payload(payload).weather
    assert weather == [f"The weather is {stored}."] * 2
