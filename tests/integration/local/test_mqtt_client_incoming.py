"""Every incoming message reaches its handler whole, however the publisher sent it.

The lab's MQTT client takes a PUBLISH without properties straight from its read buffer
(paho's way cost the station half of its time per message in a fleet command's burst) and
leaves anything else to paho, including a packet not yet whole in the buffer: messages with and without MQTT v5 properties, at QoS 0 and 1, retained or not, with
empty and large payloads, must arrive exactly as sent, in order, and a retained one must
still be kept from a handler that asked for none.
"""

from __future__ import annotations

import random
import threading
import time
from typing import TYPE_CHECKING

import paho.mqtt.client as paho
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion
from paho.mqtt.packettypes import PacketTypes
from paho.mqtt.properties import Properties

from tests.support.fault_injection_steps import wait_until
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint

if TYPE_CHECKING:
    from vahr.twin.broker import Mosquitto

TOPIC = "vahr/robots/swarm0001/events"


def _properties() -> Properties:
    properties = Properties(PacketTypes.PUBLISH)
    properties.MessageExpiryInterval = 60
    properties.UserProperty = ("sent-by", "test")
    return properties


def test_messages_with_and_without_properties_arrive_whole_and_in_order(
    mosquitto: Mosquitto,
) -> None:
    port = mosquitto.config.plain_port or 0
    received: list[tuple[str, bytes]] = []
    arrived = threading.Event()
    sent = [
        (b"", 0, None),
        (b'{"event":"accepted"}', 1, None),
        (b"x" * 300_000, 1, None),  # a length past one read of the socket
        (b'{"event":"progress"}', 0, _properties()),
        (b'{"event":"arrived"}', 1, _properties()),
        (b"last", 1, None),
    ]

    def take(topic: str, payload: bytes) -> None:
        received.append((topic, payload))
        if len(received) == len(sent):
            arrived.set()

    # Given the lab's client subscribed, and a plain paho MQTT v5 client publishing
    listener = MqttClient(MqttEndpoint(port=port)).connect()
    publisher = paho.Client(CallbackAPIVersion.VERSION2, protocol=MQTTProtocolVersion.MQTTv5)
    publisher.connect("127.0.0.1", port)
    publisher.loop_start()
    try:
        listener.subscribe("vahr/robots/+/events", take)
        # When messages of every kind are published
        for payload, qos, properties in sent:
            publisher.publish(TOPIC, payload, qos=qos, properties=properties).wait_for_publish(5)
        # Then each arrives as it was sent, in order
        assert arrived.wait(10), f"{len(received)} of {len(sent)} messages arrived"
        assert received == [(TOPIC, payload) for payload, _, _ in sent]
    finally:
        publisher.loop_stop()
        publisher.disconnect()
        listener.stop()


def test_a_burst_of_mixed_messages_arrives_whole_and_in_order(mosquitto: Mosquitto) -> None:
    port = mosquitto.config.plain_port or 0
    rng = random.Random(35)
    # Sizes from empty to past a socket read, so packets straddle the reads; every tenth
    # with properties, so paho's way and the direct one interleave.
    sent = [
        (f"{index:05d}".encode() + b"y" * rng.choice((0, 40, 900, 20_000, 70_000)), index % 2,
         _properties() if index % 10 == 0 else None)
        for index in range(2_000)
    ]  # fmt: skip
    received: list[bytes] = []
    arrived = threading.Event()

    def take(_topic: str, payload: bytes) -> None:
        received.append(payload)
        if len(received) == len(sent):
            arrived.set()

    listener = MqttClient(MqttEndpoint(port=port)).connect()
    publisher = paho.Client(CallbackAPIVersion.VERSION2, protocol=MQTTProtocolVersion.MQTTv5)
    publisher.max_inflight_messages_set(0)
    publisher.connect("127.0.0.1", port)
    publisher.loop_start()
    try:
        listener.subscribe("vahr/robots/+/events", take)
        # When they are published back to back, without waiting for each
        infos = [publisher.publish(TOPIC, payload, qos=qos, properties=props)
                 for payload, qos, props in sent]  # fmt: skip
        for info in infos:
            info.wait_for_publish(10)
        # Then every one arrives as sent, in order
        assert arrived.wait(20), f"{len(received)} of {len(sent)} messages arrived"
        assert received == [payload for payload, _, _ in sent]
    finally:
        publisher.loop_stop()
        publisher.disconnect()
        listener.stop()


def test_a_retained_message_is_kept_from_a_handler_that_asked_for_none(
    mosquitto: Mosquitto,
) -> None:
    port = mosquitto.config.plain_port or 0
    publisher = MqttClient(MqttEndpoint(port=port)).connect()
    listener = MqttClient(MqttEndpoint(port=port)).connect()
    everything: list[bytes] = []
    fresh: list[bytes] = []
    try:
        # Given a retained message on the broker
        publisher.publish(TOPIC, b"the past", retain=True)
        # When two handlers subscribe, one taking retained messages and one not, and a
        # fresh message follows
        listener.subscribe(TOPIC, lambda _t, payload: everything.append(payload))
        listener.subscribe(TOPIC, lambda _t, payload: fresh.append(payload), retained=False)
        publisher.publish(TOPIC, b"the present")
        wait_until(lambda: b"the present" in fresh and b"the present" in everything, 10)
        time.sleep(0.2)
        # Then only the first saw the past
        assert b"the past" in everything
        assert fresh == [b"the present"]
    finally:
        publisher.publish(TOPIC, b"", retain=True)
        publisher.stop()
        listener.stop()
