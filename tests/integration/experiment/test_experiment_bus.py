"""The recorder's MQTT link: live messages are recorded, retained ones (the past) are not."""

from __future__ import annotations

import threading
from datetime import UTC, datetime
from typing import TYPE_CHECKING

import paho.mqtt.client as mqtt

from vahr.experiment.bus import Bus
from vahr.protocol import Event, encode, topics

if TYPE_CHECKING:
    from vahr.twin.broker import Mosquitto


def delivered(zone: str) -> bytes:
    return encode(Event(event="delivered", thing="placebot1", zone=zone, at=datetime.now(UTC)))


def test_a_retained_delivery_from_before_is_not_recorded_but_a_live_one_is(
    mosquitto: Mosquitto,
) -> None:
    # Given a robot that retained its last delivery (zone B) before the session began
    port = mosquitto.config.plain_port
    assert port is not None
    robot = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id="robot")
    robot.connect("127.0.0.1", port)
    robot.loop_start()
    robot.publish(
        topics.robot_events("placebot1"), delivered("B"), qos=1, retain=True
    ).wait_for_publish(5)
    received: list[bytes] = []
    got_live = threading.Event()

    def on_message(topic: str, payload: bytes) -> None:
        received.append(payload)
        got_live.set()

    bus = Bus(str(mosquitto.plain_url), on_message, "vahr-experiment-retain")
    bus.start()
    try:
        # When the robot delivers again, retaining this one too
        robot.publish(
            topics.robot_events("placebot1"), delivered("D"), qos=1, retain=True
        ).wait_for_publish(5)
        assert got_live.wait(5)
    finally:
        bus.stop()
        robot.disconnect()
        robot.loop_stop()
    # Then only the live delivery is recorded
    assert [b'"zone":"D"' in payload for payload in received] == [True]
