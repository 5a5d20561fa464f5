"""Robots on a real mosquitto for the experiment's integration tests (a fixture module).

`robot_agents` runs one `robot-agent run --backend sim` process per robot of the fleet on
the test's mosquitto, faster than real time, and waits until each is online; `lab` runs
them on the local stack with the Alexa simulator attached.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
from typing import TYPE_CHECKING

import paho.mqtt.client as mqtt
import pytest

from vahr.local.alexa_host import serve_alexa
from vahr.local.robots import LOCAL_AGENT_CONFIG
from vahr.plumbing.lifetime import spawn
from vahr.protocol import decode_presence, topics

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.twin.broker import Mosquitto
    from vahr.twin.stack import LocalStack

SPEED = 50.0
# These robots run as `vahr up` runs them (this machine's clock, so no tolerance for clocks
# that disagree and task II's delivery never counts for task III's sequence; the local
# progress rate).
AGENT_CONFIG = LOCAL_AGENT_CONFIG


class RobotAgents:
    """`robot-agent run` processes, one per robot of the fleet, on a plaintext broker."""

    def __init__(self, fleet: Fleet, broker_url: str, state_dir: Path, speed: float) -> None:
        self.processes: list[subprocess.Popen[bytes]] = []
        self.fleet, self.broker_url, self.state_dir, self.speed = (
            fleet,
            broker_url,
            state_dir,
            speed,
        )

    def start(self) -> None:
        online: dict[str, threading.Event] = {t: threading.Event() for t in self.fleet.robot_things}
        watcher = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id="test-presence")

        def on_message(client: mqtt.Client, userdata: object, message: mqtt.MQTTMessage) -> None:
            parsed = topics.parse_robot_topic(message.topic)
            if parsed and decode_presence(message.payload).online:
                online[parsed[0]].set()

        watcher.on_connect = lambda c, *a: c.subscribe(topics.ALL_PRESENCE, 1)
        watcher.on_message = on_message
        port = int(self.broker_url.rsplit(":", 1)[1])
        watcher.connect("127.0.0.1", port)
        watcher.loop_start()
        config = self.state_dir / "agent.yaml"
        config.write_text(AGENT_CONFIG)
        try:
            for thing in self.fleet.robot_things:
                log = (self.state_dir / f"{thing}.log").open("wb")
                self.processes.append(
                    spawn(
                        [
                            sys.executable,
                            "-m",
                            "robot_agent.cli",
                            "run",
                            "--backend",
                            "sim",
                            "--config",
                            str(config),
                            "--thing",
                            thing,
                            "--broker",
                            self.broker_url,
                            "--sim-speed-factor",
                            str(self.speed),
                            "--state-dir",
                            str(self.state_dir / thing),
                        ],
                        started_for=self.state_dir,
                        stdout=log,
                        stderr=subprocess.STDOUT,
                        stdin=subprocess.DEVNULL,
                    )
                )
            for thing, event in online.items():
                assert event.wait(20), f"{thing} did not come online; see {self.state_dir}"
        finally:
            watcher.disconnect()
            watcher.loop_stop()

    def stop(self) -> None:
        for process in self.processes:
            process.send_signal(signal.SIGTERM)
        for process in self.processes:
            try:
                process.wait(10)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(5)


@pytest.fixture
def robot_agents(fleet: Fleet, mosquitto: Mosquitto, tmp_path: Path) -> Iterator[RobotAgents]:
    agents = RobotAgents(fleet, str(mosquitto.plain_url), tmp_path / "robots", SPEED)
    (tmp_path / "robots").mkdir()
    agents.start()
    try:
        yield agents
    finally:
        agents.stop()


class Lab:
    """The local stack with the Alexa simulator (the skill in-process) and robot agents:
    what a keyboard-and-mouse session needs, for its participant asks the assistant for the
    weather in task II."""

    def __init__(self, stack: LocalStack, robots: RobotAgents) -> None:
        self.stack, self.robots = stack, robots
        assert stack.mqtt_url is not None
        self.broker_url: str = stack.mqtt_url
        self.api_url: str = stack.api_url


@pytest.fixture
def lab(fleet: Fleet, stack: LocalStack, tmp_path: Path) -> Iterator[Lab]:
    serve_alexa(stack)
    assert stack.mqtt_url is not None
    (tmp_path / "robots").mkdir()
    agents = RobotAgents(fleet, stack.mqtt_url, tmp_path / "robots", SPEED)
    agents.start()
    try:
        yield Lab(stack, agents)
    finally:
        agents.stop()
