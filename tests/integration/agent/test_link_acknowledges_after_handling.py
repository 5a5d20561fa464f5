"""A command is acknowledged to the broker only after the robot handled it.

awscrt acknowledged a QoS 1 message as soon as it reached the process, before the agent's
event loop had seen it; a robot killed in between lost the command (the broker had its
PUBACK and never sent it again). The soak found one such command in a few hundred."""

from __future__ import annotations

import asyncio
import threading
from typing import TYPE_CHECKING

from awscrt import mqtt5

from robot_agent.config import MqttSettings
from robot_agent.link.mqtt5 import LinkSettings, Mqtt5Link
from tests.support.fault_injection_steps import wait_until
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint

if TYPE_CHECKING:
    from vahr.twin.broker import Mosquitto

TOPIC = "vahr/robots/placebot1/cmd"
BARRIER = "vahr/robots/placebot1/barrier"


class _WatchedLink(Mqtt5Link):
    """The real link, telling when a message reached it from the client library."""

    def __init__(self, settings: LinkSettings, loop: asyncio.AbstractEventLoop) -> None:
        self.received = threading.Event()
        super().__init__(settings, loop)

    def _on_publish_received(self, data: mqtt5.PublishReceivedData) -> None:
        super()._on_publish_received(data)
        self.received.set()


def _link(port: int, loop: asyncio.AbstractEventLoop) -> _WatchedLink:
    return _WatchedLink(
        LinkSettings(
            client_id="placebot1",
            host="127.0.0.1",
            port=port,
            session=MqttSettings(session_expiry_s=3600),
        ),
        loop,
    )


def test_a_message_the_robot_never_handled_is_delivered_again_when_it_is_back(
    mosquitto: Mosquitto,
) -> None:
    port = mosquitto.config.plain_port or 0
    # Given a robot whose event loop stops turning once it is connected (as if it froze)
    frozen = asyncio.new_event_loop()
    link = _link(port, frozen)
    first: list[bytes] = []
    link.add_route(TOPIC, lambda _topic, payload: first.append(payload))
    frozen.run_until_complete(link.start(10))  # returns once its subscription is in place
    # When a command reaches it, and the robot goes away before handling it
    sender = MqttClient(MqttEndpoint(port=port)).connect()
    try:
        sender.publish(TOPIC, b'{"id": "never-handled"}')
        # received by the client library, never dispatched
        assert link.received.wait(5)
        # A publish of the robot's own, once the broker acknowledged it, is a barrier: an
        # acknowledgment of the command sent too early would have reached the broker first.
        barrier = mqtt5.PublishPacket(topic=BARRIER, payload=b"", qos=mqtt5.QoS.AT_LEAST_ONCE)
        link._client.publish(barrier).result(timeout=5)
        # (its client stops without the frozen loop ever turning again)
        link._client.stop()
        assert link._stopped.wait(5)
        assert first == []
        # Then the broker delivers it again when the robot comes back
        loop = asyncio.new_event_loop()
        again: list[bytes] = []
        back = _link(port, loop)
        back.add_route(TOPIC, lambda _topic, payload: again.append(payload))
        loop.run_until_complete(back.start(10))
        loop.run_until_complete(asyncio.to_thread(wait_until, lambda: bool(again), 10))
        assert again == [b'{"id": "never-handled"}']
        loop.run_until_complete(back.stop(5))
        loop.close()
    finally:
        sender.stop()
        frozen.close()
