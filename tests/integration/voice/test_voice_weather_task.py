"""End to end on this machine: the weather task by voice, with real parts throughout.

The local stack (mosquitto, shadow service, data plane), the skill handler answering its
WeatherIntent from the experiment thing's shadow through the data plane, the room
assistant recognizing the robot's spoken question and speaking the skill's answer, and a
real `robot-agent run` process with the room voice and the simulator backend. The robot
must arrive in A when sunny and in C when rainy, and its events must carry what it heard.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from tests.conftest import load_event
from vahr.local.room_assistant import offline_room_assistant
from vahr.plumbing.lifetime import spawn
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.protocol import encode, new_command, topics
from vahr.protocol.shadow import ExperimentState

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack

ROOT = Path(__file__).resolve().parents[3]
AGENT = [sys.executable, "-m", "robot_agent.cli"]
TASK_TIMEOUT_S = 60.0


@pytest.fixture
def skill_ask(stack: LocalStack, monkeypatch: pytest.MonkeyPatch) -> Any:
    """The real skill handler, on the local data plane, asked its WeatherIntent."""
    for name, value in {
        "AWS_ACCESS_KEY_ID": "testing",
        "AWS_SECRET_ACCESS_KEY": "testing",
        "AWS_DEFAULT_REGION": "us-east-1",
        "VAHR_IOT_DATA_ENDPOINT": stack.api_url,
    }.items():
        monkeypatch.setenv(name, value)
    monkeypatch.delenv("VAHR_SKILL_ID", raising=False)
    from skill.app import make_lambda_handler

    handler = make_lambda_handler()

    def ask(utterance: str) -> str | None:
        # The room only accepts weather questions, so each is the skill's WeatherIntent.
        response = handler(load_event("alexa_weather"), None)
        speech: str = response["response"]["outputSpeech"]["ssml"]
        return speech.removeprefix("<speak>").removesuffix("</speak>").strip()

    return ask


def set_weather(stack: LocalStack, weather: str) -> None:
    import boto3

    client = boto3.client("iot-data", endpoint_url=stack.api_url, region_name="us-east-1")
    client.update_thing_shadow(
        thingName="vahr-experiment", payload=ExperimentState(weather=weather).to_payload()
    )  # type: ignore[arg-type]


class EventLog:
    """Every event of one robot, as a subscriber on the broker sees it."""

    def __init__(self, port: int, thing: str) -> None:
        self.events: list[dict[str, Any]] = []
        self._changed = threading.Condition()
        self.client = MqttClient(MqttEndpoint(port=port)).connect()
        self.client.subscribe(topics.robot_events(thing), self._on_event)

    def _on_event(self, topic: str, payload: bytes) -> None:
        with self._changed:
            self.events.append(json.loads(payload))
            self._changed.notify_all()

    def wait_for(
        self, kind: str, timeout_s: float, command_id: str | None = None
    ) -> dict[str, Any]:
        deadline = time.monotonic() + timeout_s
        with self._changed:
            while True:
                for event in self.events:
                    if command_id is not None and event.get("command_id") != command_id:
                        continue
                    if event["event"] in (kind, "failed"):
                        return event
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise AssertionError(f"no {kind} event within {timeout_s} s: {self.events}")
                self._changed.wait(remaining)


@pytest.mark.slow
@pytest.mark.parametrize(("weather", "zone"), [("sunny", "A"), ("rainy", "C")])
def test_the_robot_asks_the_weather_by_voice_and_delivers(
    stack: LocalStack, skill_ask: Any, tmp_path: Path, weather: str, zone: str
) -> None:
    assert stack.config.mqtt_port is not None
    port = stack.config.mqtt_port
    broker = f"mqtt://127.0.0.1:{port}"
    # Given the experiment's weather, the room assistant and a robot with the room voice
    set_weather(stack, weather)
    room_client = MqttClient(MqttEndpoint(port=port)).connect()
    assistant = offline_room_assistant(room_client, skill_ask).start()
    log = EventLog(port, "placebot1")
    env = {**os.environ, "VAHR_ROOM_BROKER": broker, "PYTHONPATH": str(ROOT)}
    agent = spawn(
        [*AGENT, "run", "--thing", "placebot1", "--broker", broker,
         "--voice", "robot_agent.voice.factories:room", "--sim-speed-factor", "20",
         "--state-dir", str(tmp_path / "agent")],
        started_for=tmp_path / "agent", cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
        stderr=(tmp_path / "agent.log").open("wb"),
    )  # fmt: skip
    try:
        presence = threading.Event()
        with MqttClient(MqttEndpoint(port=port)) as watcher:
            watcher.subscribe(
                topics.robot_presence("placebot1"),
                lambda _t, p: presence.set() if json.loads(p).get("online") else None,
            )
            assert presence.wait(45.0), (tmp_path / "agent.log").read_text()
            # When the person asks for a weather delivery
            command = new_command("weather_delivery", {}, source="console")
            watcher.publish(topics.robot_cmd("placebot1"), encode(command))
        # Then the robot delivers to the weather's zone
        delivered = log.wait_for("delivered", TASK_TIMEOUT_S, command.id)
        assert delivered["event"] == "delivered", (tmp_path / "agent.log").read_text()
        assert delivered["zone"] == zone
        # And its events show what it said, heard and understood
        mine = [e for e in log.events if e.get("command_id") == command.id]
        said = [e["text"] for e in mine if e["event"] == "said"]
        heard = [e["text"] for e in mine if e["event"] == "heard"]
        interpreted = [e["intent"] for e in mine if e["event"] == "interpreted"]
        assert said[0] == "Alexa, ask robot fleet what the weather is"
        assert heard == [f"the weather is {weather}"]
        assert interpreted == [weather]
    finally:
        agent.terminate()
        try:
            agent.wait(10)
        except subprocess.TimeoutExpired:
            agent.kill()
            agent.wait(5)
        log.client.stop()
        assistant.stop()
        room_client.stop()
