"""Fuzz: ASK request envelopes into the skill handler.

Real-shaped envelopes from tests/events/ are mutated one to three places at a time (a value
replaced by any JSON, a key removed, a slot's spoken value or resolved id made up, an
intent or request type renamed). Properties: the handler always returns; the response is a
valid ASK response envelope whose speech, if any, is well-formed SSML (a hostile slot value
cannot inject markup); every command it publishes is a valid command message to a real
topic. The robots are the real shadow store answering at once, as a robot would.
"""

from __future__ import annotations

import copy
import json
import xml.etree.ElementTree as ElementTree
from pathlib import Path
from typing import Any

import msgspec
from hypothesis import given, settings
from hypothesis import strategies as st

from skill.app import make_lambda_handler
from skill.config import SkillConfig
from skill.errors import GatewayError, ShadowConflict
from tests.fuzz.strategies import json_values, paths_in, text
from tests.fuzz.tally import TALLY, budget
from tests.unit.skill.skill_testkit import check_response
from vahr.domain import load_fleet
from vahr.protocol import Reported, decode_command, topics
from vahr.twin.shadow_store import ShadowError, ShadowStore

EVENTS = sorted((Path(__file__).parents[1] / "events").glob("alexa_*.json"))
ENVELOPES = {path.stem: json.loads(path.read_text()) for path in EVENTS}
FLEET = load_fleet()
INTENTS = [
    "NavigateIntent", "DeliverIntent", "WeatherDeliveryIntent", "SequentialDeliveryIntent",
    "StatusIntent", "EmergencyStopIntent", "WeatherIntent", "AMAZON.HelpIntent",
    "AMAZON.StopIntent", "AMAZON.CancelIntent", "AMAZON.FallbackIntent",
]  # fmt: skip


class StoreRobots:
    """The `RobotGateway` over a real in-memory shadow store whose robots acknowledge
    every valid command at once (what robot-agent would report)."""

    def __init__(self) -> None:
        self.store = ShadowStore(None)
        self.published: list[tuple[str, bytes]] = []
        for thing in FLEET.robot_things:
            self.store.update(
                thing, None, Reported(status="idle", zone="LOADING", connected=True).to_payload()
            )

    def publish(self, topic: str, payload: bytes) -> None:
        self.published.append((topic, payload))
        command = decode_command(payload, FLEET)
        things = (
            FLEET.robot_things
            if topic == topics.FLEET_CMD
            else [topics.parse_robot_topic(topic)[0]]  # type: ignore[index]
        )
        for thing in things:
            last = {"id": command.id, "action": command.action, "result": "accepted"}
            body = msgspec.json.encode({"state": {"reported": {"last_command": last}}})
            self.store.update(thing, None, body)

    def get_shadow(self, thing: str) -> bytes | None:
        try:
            return msgspec.json.encode(self.store.get(thing))
        except ShadowError as err:
            if err.code == 404:
                return None
            raise GatewayError(err.message) from err

    def update_shadow(self, thing: str, payload: bytes) -> bytes:
        try:
            return msgspec.json.encode(self.store.update(thing, None, payload).accepted)
        except ShadowError as err:
            if err.code == 409:
                raise ShadowConflict(err.message) from err
            raise GatewayError(err.message) from err


@st.composite
def envelopes(draw: st.DrawFn) -> dict[str, Any]:
    envelope = copy.deepcopy(ENVELOPES[draw(st.sampled_from(sorted(ENVELOPES)))])
    for _ in range(draw(st.integers(1, 3))):
        paths = paths_in(envelope)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent: Any = envelope
        for step in path[:-1]:
            parent = parent[step]
        key = path[-1]
        kind = draw(st.sampled_from(["json", "text", "delete", "intent", "type"]))
        if kind == "delete" and isinstance(parent, dict):
            del parent[key]
        elif kind == "intent":
            envelope.setdefault("request", {})
            if isinstance(envelope["request"], dict):
                envelope["request"].setdefault("intent", {})
                if isinstance(envelope["request"]["intent"], dict):
                    envelope["request"]["intent"]["name"] = draw(
                        st.one_of(st.sampled_from(INTENTS), text)
                    )
        elif kind == "type" and isinstance(envelope.get("request"), dict):
            envelope["request"]["type"] = draw(
                st.one_of(
                    st.sampled_from(
                        [
                            "IntentRequest",
                            "LaunchRequest",
                            "SessionEndedRequest",
                            "CanFulfillIntentRequest",
                            "Messaging.MessageReceived",
                        ]
                    ),  # fmt: skip
                    text,
                )
            )
        else:
            parent[key] = draw(json_values(6) if kind == "json" else text)
    return envelope


HANDLER = make_lambda_handler(SkillConfig(ack_timeout_s=0.05), StoreRobots())


def _speech_is_well_formed(response: dict[str, Any]) -> None:
    for part in (response.get("response", {}), response.get("response", {}).get("reprompt")):
        speech = (part or {}).get("outputSpeech")
        if speech and speech.get("type") == "SSML":
            ElementTree.fromstring(speech["ssml"])  # raises on injected or broken markup


@given(envelope=envelopes())
@settings(max_examples=budget(150))
def test_the_skill_always_answers_with_valid_speech(envelope: dict[str, Any]) -> None:
    gateway = StoreRobots()
    handler = make_lambda_handler(SkillConfig(ack_timeout_s=0.05), gateway)
    response = handler(envelope, None)
    check_response(response)
    _speech_is_well_formed(response)
    for topic, payload in gateway.published:
        parsed = topics.parse_robot_topic(topic)
        assert topic == topics.FLEET_CMD or (parsed and parsed[1] == "cmd"), topic
        decode_command(payload, FLEET)
    if gateway.published:
        TALLY.accepted("ASK envelope into the skill")
    else:
        TALLY.rejected("ASK envelope into the skill", "no command")
