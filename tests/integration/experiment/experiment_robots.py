"""Robots on a real mosquitto for the experiment's integration tests (a fixture module).

`robots_on_broker` runs the real robot core (`robot_agent.core.Executor` with the simulator
backend) for every robot of the fleet, linked to the broker by a minimal paho bridge, so a
session can be run end to end over real MQTT before `vahr up` is available. The bridge only
carries messages; everything the robots decide is the executor's.
"""

from __future__ import annotations

import asyncio
import threading
from typing import TYPE_CHECKING

import paho.mqtt.client as mqtt
import pytest

from robot_agent.backends.sim import SimBackend
from robot_agent.core.clock import ScaledClock
from robot_agent.core.executor import Executor
from vahr.protocol import ProtocolError, decode_command, decode_event, encode, topics

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.local.broker import Mosquitto
    from vahr.protocol import Event, Fleet

SPEED = 50.0


class RobotsOnBroker:
    def __init__(self, fleet: Fleet, port: int, speed: float) -> None:
        self.fleet = fleet
        self.speed = speed
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, name="robots")
        self.client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id="test-robots")
        self.port = port
        self.executors: dict[str, Executor] = {}
        self.ready = threading.Event()

    def _publish_event(self, event: Event) -> None:
        self.client.publish(topics.robot_events(event.thing), encode(event), qos=1)

    def start(self) -> None:
        self.thread.start()
        clock = ScaledClock(self.speed)

        async def build() -> None:
            for robot in self.fleet.robots:
                self.executors[robot.thing] = Executor(
                    thing=robot.thing,
                    fleet=self.fleet,
                    clock=clock,
                    backend=SimBackend(start=robot.start, clock=clock),
                    publish_state=lambda state: None,
                    publish_event=self._publish_event,
                )

        asyncio.run_coroutine_threadsafe(build(), self.loop).result(5)
        self.client.on_connect = lambda c, *a: c.subscribe(
            [("vahr/robots/+/cmd", 1), (topics.FLEET_CMD, 1), (topics.ALL_EVENTS, 1)]
        )
        self.client.on_subscribe = lambda *a: self.ready.set()
        self.client.on_message = self._on_message
        self.client.connect("127.0.0.1", self.port)
        self.client.loop_start()
        assert self.ready.wait(10), "the robots did not subscribe"

    def _on_message(self, client: mqtt.Client, userdata: object, message: mqtt.MQTTMessage) -> None:
        parsed = topics.parse_robot_topic(message.topic)
        if parsed is not None and parsed[1] == "events":
            event = decode_event(message.payload)
            for executor in self.executors.values():
                self.loop.call_soon_threadsafe(executor.peer_event, event)
            return
        try:
            command = decode_command(message.payload, self.fleet)
        except ProtocolError:
            return
        targets = self.executors.values() if parsed is None else [self.executors[parsed[0]]]
        for executor in targets:
            self.loop.call_soon_threadsafe(executor.execute, command)

    def stop(self) -> None:
        async def close() -> None:
            for executor in self.executors.values():
                await executor.close()

        asyncio.run_coroutine_threadsafe(close(), self.loop).result(10)
        self.client.disconnect()
        self.client.loop_stop()
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(10)
        self.loop.close()


@pytest.fixture
def robots_on_broker(fleet: Fleet, mosquitto: Mosquitto) -> Iterator[RobotsOnBroker]:
    robots = RobotsOnBroker(fleet, mosquitto.config.plain_port or 0, SPEED)
    robots.start()
    try:
        yield robots
    finally:
        robots.stop()
