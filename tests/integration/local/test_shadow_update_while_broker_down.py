"""A shadow update the data plane stored is answered as stored, even with the broker down.

The data plane answered 500 ("Internal service failure") for a desired-state update it had
already written to the shadow, because publishing the update's notifications raised while
the shadow service was disconnected. The robot then read its desired state on reconnecting
and ran a command its sender had been told had failed (the soak counted it "ran after
refusal")."""

from __future__ import annotations

import json
import time
from typing import TYPE_CHECKING

from tests.support.fault_injection_steps import wait_until
from vahr.plumbing.client import call
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.protocol import topics

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack

COMMAND = {"id": "desired-while-down", "action": "navigate", "params": {"zone": "B"}}


def test_a_desired_command_written_while_the_broker_is_down_is_accepted_and_delivered(
    stack: LocalStack,
) -> None:
    assert stack.broker is not None and stack.config.mqtt_port is not None
    port = stack.config.mqtt_port
    deltas: list[bytes] = []
    # (a robot's session is persistent: what is sent while it reconnects is queued for it)
    robot = MqttClient(
        MqttEndpoint(port=port), client_id="placebot1-listener", session_expiry_s=600
    ).connect()
    robot.subscribe(
        topics.shadow("placebot1", "update/delta"), lambda _t, payload: deltas.append(payload)
    )
    # Given the broker saved its sessions (every second), then crashed, and the shadow
    # service lost its connection
    database = stack.broker.config.state_dir / "mosquitto.db"
    since = time.time()
    wait_until(lambda: database.exists() and database.stat().st_mtime > since, 10)
    stack.broker.kill()
    assert stack._service_client is not None
    wait_until(lambda: not stack._service_client._client.is_connected(), 10)
    try:
        # When a sender writes a command as the robot's desired state
        answer = call(
            stack.api_url,
            "POST",
            "/things/placebot1/shadow",
            {"state": {"desired": {"command": COMMAND}}},
        )
        # Then the data plane answers with the accepted document, and the shadow holds it
        assert answer["state"]["desired"]["command"]["id"] == COMMAND["id"]
        shadow = call(stack.api_url, "GET", "/things/placebot1/shadow")
        assert shadow["state"]["desired"]["command"]["id"] == COMMAND["id"]
    finally:
        stack.broker.start()
    # And once the broker is back, the robot is told of it
    wait_until(lambda: bool(deltas), 30)
    delta = json.loads(deltas[0])
    assert delta["state"]["command"]["id"] == COMMAND["id"]
    robot.stop()
