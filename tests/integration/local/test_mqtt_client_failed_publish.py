"""A publish the lab's MQTT client reports as failed is never sent later.

paho keeps a QoS 1 message it could not send (no connection) and sends it after it
reconnects. The data plane answered 503 for such a publish, so the skill told the user it
could not reach the robot, and the robot still ran the command once the broker was back
(25 of 25 such commands arrived before the fix)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import pytest

from tests.support.fault_injection_steps import wait_until
from vahr.errors import VahrError
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint

if TYPE_CHECKING:
    from vahr.twin.broker import Mosquitto

TOPIC = "vahr/robots/placebot1/cmd"
# More than paho's 20 messages in flight, so a queue blocked by withdrawn messages shows.
FAILED_PUBLISHES = 25


def test_a_publish_refused_while_the_broker_is_down_never_arrives_after_it_returns(
    mosquitto: Mosquitto,
) -> None:
    port = mosquitto.config.plain_port or 0
    received: list[bytes] = []
    listener = MqttClient(MqttEndpoint(port=port), client_id="listener", session_expiry_s=600)
    listener.subscribe(TOPIC, lambda _topic, payload: received.append(payload))
    listener.connect()
    publisher = MqttClient(MqttEndpoint(port=port)).connect()
    try:
        # Given the broker went down under a connected publisher
        mosquitto.kill()
        wait_until(lambda: not publisher._client.is_connected(), 10)
        # When commands are published, then the caller is told each one failed
        for attempt in range(FAILED_PUBLISHES):
            with pytest.raises(VahrError, match="cannot publish"):
                publisher.publish(TOPIC, b'{"id": "told-failed-%d"}' % attempt)
        # And when the broker is back and both clients have reconnected
        mosquitto.start()
        wait_until(lambda: publisher._client.is_connected(), 20)
        wait_until(lambda: listener._client.is_connected(), 20)
        for attempt in range(FAILED_PUBLISHES):
            publisher.publish(TOPIC, b'{"id": "after-%d"}' % attempt)
        expected = [b'{"id": "after-%d"}' % attempt for attempt in range(FAILED_PUBLISHES)]
        wait_until(lambda: len(received) >= FAILED_PUBLISHES, 10)
        time.sleep(0.5)  # nothing more is expected; give a late resend the time to show
        # Then every command sent after the broker returned arrived, and none of the others
        assert received == expected
    finally:
        publisher.stop()
        listener.stop()


def test_a_publish_fails_at_once_rather_than_hanging_when_not_connected(
    mosquitto: Mosquitto,
) -> None:
    publisher = MqttClient(MqttEndpoint(port=mosquitto.config.plain_port or 0)).connect()
    try:
        mosquitto.kill()
        wait_until(lambda: not publisher._client.is_connected(), 10)
        started = time.monotonic()
        with pytest.raises(VahrError, match="not connected"):
            publisher.publish(TOPIC, b"{}")
        assert time.monotonic() - started < 1.0
    finally:
        publisher.stop()
        mosquitto.start()
