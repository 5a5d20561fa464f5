"""The robots' link hands received messages to their handlers in arrival order, and a
message with thousands of handlers (a fleet command to a swarm) does not hold the event
loop until the last one has run."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from robot_agent.link.mqtt5 import LinkSettings, Mqtt5Link
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.twin.broker import Mosquitto

FLEET = "vahr/fleet/cmd"
ONE = "vahr/robots/swarm0001/cmd"
ROBOTS = 1000


async def _receive(port: int) -> tuple[list[str], int]:
    loop = asyncio.get_running_loop()
    link = Mqtt5Link(LinkSettings(client_id="swarm-link", host="127.0.0.1", port=port), loop)
    heard: list[str] = []

    def robot(index: int) -> Callable[[str, bytes], None]:
        return lambda _topic, payload: heard.append(f"{payload.decode()}{index}")

    for index in range(ROBOTS):
        link.add_route(FLEET, robot(index))
    link.add_route(ONE, lambda _t, payload: heard.append(payload.decode()))
    # Other work on the loop meanwhile: each turn of the loop it gets notes where the
    # handlers had come to.
    interleaved: list[int] = []
    running = True

    def other_work() -> None:
        if running:
            interleaved.append(len(heard))
            loop.call_soon(other_work)

    await link.start(10)
    try:
        loop.call_soon(other_work)
        sender = MqttClient(MqttEndpoint(port=port)).connect()
        try:
            # When a fleet message, one robot's message and a second fleet message arrive
            for topic, payload in ((FLEET, "a"), (ONE, "b"), (FLEET, "c")):
                sender.publish(topic, payload.encode())
            async with asyncio.timeout(20):
                while len(heard) < 2 * ROBOTS + 1:
                    await asyncio.sleep(0.01)
        finally:
            sender.stop()
    finally:
        running = False
        await link.stop(5)
    # Turns of the loop taken while the first message was half way through its handlers.
    during = sum(1 for count in interleaved if 0 < count < ROBOTS)
    return heard, during


def test_messages_reach_handlers_in_arrival_order_without_holding_the_loop(
    mosquitto: Mosquitto,
) -> None:
    heard, turns_during = asyncio.run(_receive(mosquitto.config.plain_port or 0))
    # Then every handler of the first fleet message ran before the robot's message, and
    # that before any handler of the second
    expected = [f"a{i}" for i in range(ROBOTS)] + ["b"] + [f"c{i}" for i in range(ROBOTS)]
    assert heard == expected
    # and other work on the loop ran while the first message's handlers were being called
    assert turns_during >= 2
