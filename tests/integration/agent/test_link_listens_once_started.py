"""A link that has started is listening: a command sent the moment it starts arrives.

`Mqtt5Link.start` returned on the CONNACK, before the broker had acknowledged the link's
subscriptions; a command published in between matched no subscription of the new session
and the broker dropped it. The soak lost its first command so (a ping to a swarm robot,
sent 4 ms after the swarm of 100 robots started)."""

from __future__ import annotations

import asyncio
import threading
from typing import TYPE_CHECKING

from robot_agent.config import MqttSettings
from robot_agent.link.mqtt5 import LinkSettings, Mqtt5Link
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint

if TYPE_CHECKING:
    from vahr.twin.broker import Mosquitto

ROBOTS = 500  # a swarm's worth of command topics: several SUBSCRIBE packets


def test_a_command_sent_as_soon_as_the_link_started_is_delivered(mosquitto: Mosquitto) -> None:
    port = mosquitto.config.plain_port or 0
    # Given a sender already connected, and a new robot link routing many command topics
    sender = MqttClient(MqttEndpoint(port=port)).connect()
    loop = asyncio.new_event_loop()
    link = Mqtt5Link(
        LinkSettings(
            client_id="vahr-swarm-new",
            host="127.0.0.1",
            port=port,
            session=MqttSettings(session_expiry_s=3600),
        ),
        loop,
    )
    arrived = threading.Event()
    last = f"vahr/robots/swarm{ROBOTS:04d}/cmd"
    for number in range(1, ROBOTS + 1):
        topic = f"vahr/robots/swarm{number:04d}/cmd"
        link.add_route(topic, lambda t, _payload: arrived.set() if t == last else None)
    try:
        # When the link has started and the sender publishes at once to the last robot
        loop.run_until_complete(link.start(10))
        sender.publish(last, b'{"id": "sent-at-start"}')
        # Then the robot receives it
        loop.run_until_complete(asyncio.to_thread(arrived.wait, 10))
        assert arrived.is_set(), "the command sent as the link started never arrived"
    finally:
        loop.run_until_complete(link.stop(5))
        loop.close()
        sender.stop()
