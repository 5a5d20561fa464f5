"""The shadow service misses no update across a broker restart.

A robot reports its state only when it changes. Its first report after the broker came
back often arrives before the shadow service has reconnected; with a clean session the
broker dropped it, and a robot that then stayed idle left its shadow stale (the soak found
shadows still saying `navigating` for robots long idle)."""

from __future__ import annotations

import json
import time
from typing import TYPE_CHECKING

from tests.support.fault_injection_steps import crash_and_restart_broker, wait_until
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.protocol import topics
from vahr.twin.shadow_store import ShadowError

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack


def _reported(stack: LocalStack, thing: str) -> dict[str, object] | None:
    assert stack.store is not None
    try:
        return dict(stack.store.get(thing)["state"]["reported"])
    except (ShadowError, KeyError):
        return None


def test_an_update_sent_before_the_shadow_service_reconnects_is_applied(
    stack: LocalStack,
) -> None:
    assert stack.broker is not None and stack.config.mqtt_port is not None
    port = stack.config.mqtt_port
    robot = MqttClient(MqttEndpoint(port=port)).connect()
    robot.publish(
        topics.shadow("placebot1", "update"), b'{"state":{"reported":{"status":"navigating"}}}'
    )
    wait_until(lambda: (_reported(stack, "placebot1") or {}).get("status") == "navigating", 10)
    robot.stop()
    # Given the broker saved its sessions (it does every second), then crashed and came
    # back, and the shadow service has not reconnected yet
    database = stack.broker.config.state_dir / "mosquitto.db"
    since = time.time()
    wait_until(lambda: database.exists() and database.stat().st_mtime > since, 10)
    crash_and_restart_broker(stack.broker)
    robot = MqttClient(MqttEndpoint(port=port)).connect()
    try:
        # When the robot reports at once that it is idle
        robot.publish(
            topics.shadow("placebot1", "update"), b'{"state":{"reported":{"status":"idle"}}}'
        )
        # Then the shadow says so once the service is back
        wait_until(lambda: (_reported(stack, "placebot1") or {}).get("status") == "idle", 20)
    finally:
        robot.stop()
    print(json.dumps(_reported(stack, "placebot1")))
