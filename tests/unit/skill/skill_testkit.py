"""Test doubles and helpers for the skill's tests (imported by conftest and the tests).

`RobotDoubles` stands in for robot-agent at the far end of the shadow: it watches what the
skill publishes (moto's `published_payloads`) and, from another thread, writes the robot's
reported state through the same iot-data API a real robot's shadow update would reach.
"""

from __future__ import annotations

import json
import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from moto.core import DEFAULT_ACCOUNT_ID
from moto.iotdata.models import iotdata_backends

from vahr.protocol import LastCommand, Reported, decode_command, topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain import Fleet
    from vahr.protocol import Command

REGION = "us-east-1"


def published() -> list[tuple[str, bytes]]:
    """Every message the skill published, in order, as moto recorded it."""
    return list(iotdata_backends[DEFAULT_ACCOUNT_ID][REGION].published_payloads)


@dataclass
class RobotBehaviour:
    """How one robot double answers: after `delay_s`, with `result` (None = never)."""

    result: str | None = "accepted"
    reason: str | None = None
    delay_s: float = 0.2
    connected: bool = True
    reported: Callable[[Command], Reported] | None = None


@dataclass
class RobotDoubles:
    """Robot doubles answering the skill's commands through their shadows."""

    iot_data: Any
    fleet: Fleet
    behaviours: dict[str, RobotBehaviour] = field(default_factory=dict)
    answered: list[tuple[str, str, float]] = field(default_factory=list)  # thing, id, time
    _stop: threading.Event = field(default_factory=threading.Event)
    _thread: threading.Thread | None = None

    def behave(self, thing: str, behaviour: RobotBehaviour) -> None:
        self.behaviours[thing] = behaviour

    def report(self, thing: str, state: Reported) -> None:
        self.iot_data.update_thing_shadow(thingName=thing, payload=state.to_payload())

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="robot-doubles", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
            assert not self._thread.is_alive(), "robot doubles did not stop"

    def _run(self) -> None:
        seen = 0
        due: list[tuple[float, str, Command]] = []
        while not self._stop.wait(0.01):
            messages = published()
            for topic, payload in messages[seen:]:
                for thing in self._recipients(topic):
                    behaviour = self.behaviours.get(thing, RobotBehaviour())
                    if behaviour.result is not None:
                        command = decode_command(payload, self.fleet)
                        due.append((time.monotonic() + behaviour.delay_s, thing, command))
            seen = len(messages)
            now = time.monotonic()
            for item in [item for item in due if item[0] <= now]:
                due.remove(item)
                self._answer(item[1], item[2])

    def _recipients(self, topic: str) -> list[str]:
        if topic == topics.FLEET_CMD:
            return list(self.fleet.robot_things)
        parsed = topics.parse_robot_topic(topic)
        return [parsed[0]] if parsed and parsed[1] == "cmd" else []

    def _answer(self, thing: str, command: Command) -> None:
        behaviour = self.behaviours.get(thing, RobotBehaviour())
        if behaviour.reported is not None:
            state = behaviour.reported(command)
        else:
            zone = getattr(command.params, "zone", None)
            state = Reported(
                status="navigating" if command.is_motion else "stopped",
                destination=zone,
                task=command.action,
                connected=behaviour.connected,
            )
        last = LastCommand(command.id, command.action, behaviour.result, behaviour.reason)  # type: ignore[arg-type]
        self.report(thing, Reported(**{**_fields(state), "last_command": last}))
        self.answered.append((thing, command.id, time.monotonic()))


def _fields(state: Reported) -> dict[str, Any]:
    return {name: getattr(state, name) for name in state.__struct_fields__}


def check_response(response: dict[str, Any]) -> None:
    """The response is a valid ASK response envelope: ask-sdk-model reads it back unchanged."""
    from ask_sdk_core.serialize import DefaultSerializer

    serializer = DefaultSerializer()
    parsed = serializer.deserialize(json.dumps(response), "ask_sdk_model.ResponseEnvelope")
    assert serializer.serialize(parsed) == response


def speech(response: dict[str, Any]) -> str:
    """The words Alexa would speak for a (checked) skill response."""
    check_response(response)
    ssml: str = response["response"]["outputSpeech"]["ssml"]
    assert ssml.startswith("<speak>") and ssml.endswith("</speak>")
    return ssml.removeprefix("<speak>").removesuffix("</speak>")


def reprompt(response: dict[str, Any]) -> str:
    ssml: str = response["response"]["reprompt"]["outputSpeech"]["ssml"]
    return ssml.removeprefix("<speak>").removesuffix("</speak>")
