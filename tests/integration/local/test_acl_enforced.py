"""The broker enforces the robot policy: placebot2's certificate cannot command placebot1
nor touch its shadow (MQTT 5 answers a denied publish with PUBACK 0x87)."""

from __future__ import annotations

import json
import threading
from typing import TYPE_CHECKING

import pytest

from vahr.plumbing.mqtt import MqttClient, MqttEndpoint, PublishDenied
from vahr.protocol import new_command, topics

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.twin.stack import LocalStack


def _robot(stack: LocalStack, thing: str, tmp_path: Path) -> MqttClient:
    assert stack.ca is not None
    credentials = stack.ca.issue_client(thing, tmp_path / thing)
    endpoint = MqttEndpoint(port=stack.config.mqtts_port, credentials=credentials)
    return MqttClient(endpoint, client_id=thing)


def test_a_robot_cannot_command_another_robot(local_stack: LocalStack, tmp_path: Path) -> None:
    received: list[bytes] = []
    got = threading.Event()
    with MqttClient(local_stack.service_endpoint()) as watcher:
        watcher.subscribe(
            topics.robot_cmd("placebot1"), lambda _t, p: (received.append(p), got.set())
        )
        with _robot(local_stack, "placebot2", tmp_path) as intruder:
            command = new_command("navigate", {"zone": "A"}, source="robot:placebot2")
            # When placebot2 publishes to placebot1's command topic
            with pytest.raises(PublishDenied, match="Not authorized"):
                intruder.publish(
                    topics.robot_cmd("placebot1"),
                    json.dumps(
                        {
                            "id": command.id,
                            "action": "navigate",
                            "params": {"zone": "A"},
                            "issued_at": "2026-11-22T05:00:00Z",
                            "source": "robot:placebot2",
                        }
                    ).encode(),
                )
            # But its own events go through
            intruder.publish(topics.robot_events("placebot2"), b'{"event":"ping"}')
        # Then placebot1's command topic never carried it
        assert not got.wait(0.5)
        assert received == []


def test_a_robot_cannot_update_another_robots_shadow(
    local_stack: LocalStack, tmp_path: Path
) -> None:
    store = local_stack.store
    assert store is not None
    store.update("placebot1", None, b'{"state":{"reported":{"zone":"A"}}}')
    before = store.get("placebot1")["version"]
    with _robot(local_stack, "placebot2", tmp_path) as intruder:
        with pytest.raises(PublishDenied):
            intruder.publish(
                topics.shadow("placebot1", "update"), b'{"state":{"reported":{"zone":"D"}}}'
            )
        # Its own shadow it may update
        intruder.publish(topics.shadow("placebot2", "update"), b'{"state":{"reported":{"ok":1}}}')
    document = store.get("placebot1")
    assert document["version"] == before
    assert document["state"]["reported"] == {"zone": "A"}


def test_a_robot_hears_its_own_commands_and_the_fleet_but_not_its_peers(
    local_stack: LocalStack, tmp_path: Path
) -> None:
    heard: list[str] = []
    done = threading.Event()

    def on_message(topic: str, _payload: bytes) -> None:
        heard.append(topic)
        if topic == topics.FLEET_CMD:
            done.set()

    with _robot(local_stack, "placebot2", tmp_path) as robot:
        # Subscribing to a peer's topic is granted but nothing is delivered (mosquitto).
        robot.subscribe("vahr/robots/+/cmd", on_message)
        robot.subscribe(topics.FLEET_CMD, on_message)
        with MqttClient(local_stack.service_endpoint()) as skill:
            skill.publish(topics.robot_cmd("placebot1"), b"{}")
            skill.publish(topics.robot_cmd("placebot2"), b"{}")
            skill.publish(topics.FLEET_CMD, b"{}")
        assert done.wait(5)
    assert topics.robot_cmd("placebot1") not in heard
    assert topics.robot_cmd("placebot2") in heard


def test_the_presence_rule_sets_connected_in_the_shadow(
    local_stack: LocalStack, tmp_path: Path
) -> None:
    store = local_stack.store
    assert store is not None
    seen = threading.Event()
    with MqttClient(local_stack.service_endpoint()) as watcher:
        watcher.subscribe(
            topics.shadow("placebot2", "update/accepted"),
            lambda _t, p: seen.set() if b"connected" in p else None,
        )
        with _robot(local_stack, "placebot2", tmp_path) as robot:
            robot.publish(
                topics.robot_presence("placebot2"),
                b'{"online": false, "at": "2026-11-22T05:00:00Z"}',
                retain=True,
            )
        assert seen.wait(5)
    assert store.get("placebot2")["state"]["reported"]["connected"] is False
