"""Broker crashes: a robot-agent comes back by itself after mosquitto is killed (SIGKILL)
and restarted, and every command sent after it is back runs exactly once. The longest
recovery is printed for docs/reliability.md."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import pytest

from tests.integration.agent.harness import command
from tests.support.fault_injection_steps import crash_and_restart_broker, wait_until
from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.integration.agent.harness import AgentProcess
    from vahr.twin.broker import Mosquitto

RESTARTS = 3
# awscrt retries with full jitter between 250 ms and 30 s; three quick failures stay far
# below the maximum, so a recovery beyond this is a real stall.
RECOVERY_BOUND_S = 20.0


def _saved_since(database: Path, since: float) -> bool:
    return database.exists() and database.stat().st_mtime > since


@pytest.mark.slow
def test_the_agent_recovers_from_broker_crashes_and_runs_each_command_once(
    mosquitto: Mosquitto, start_agent: Callable[..., AgentProcess], tmp_path: Path
) -> None:
    from tests.integration.agent.harness import WireTap

    agent = start_agent("placebot1")
    port = mosquitto.config.plain_port or 0
    tap = WireTap(port)
    try:
        tap.wait_for(lambda m: m.topic == topics.robot_presence("placebot1"), 30)
        recoveries = []
        database = mosquitto.config.state_dir / "mosquitto.db"
        for restart in range(RESTARTS):
            # Given the broker has saved the agent's session since it was last seen serving
            subscribed_at = time.time()
            wait_until(lambda since=subscribed_at: _saved_since(database, since), 10)
            # When the broker crashes and comes back after half a second
            crash_and_restart_broker(mosquitto, down_s=0.5)
            tap.close()
            back_at = time.monotonic()
            tap = WireTap(port)
            # Then the agent reconnects and answers a command sent now, exactly once
            command_id = f"after-crash-{restart}"
            tap.publish(topics.robot_cmd("placebot1"), command(command_id, "ping"))
            tap.event("placebot1", "accepted", command_id, timeout_s=RECOVERY_BOUND_S)
            recoveries.append(time.monotonic() - back_at)
            kinds = [e["event"] for e in tap.events("placebot1", command_id)]
            assert kinds.count("accepted") == 1, kinds
        assert agent.process.poll() is None, agent.log()[-2000:]
        print(f"\nlongest recovery after a broker restart: {max(recoveries):.2f} s "
              f"(all: {', '.join(f'{r:.2f}' for r in recoveries)})")  # fmt: skip
    finally:
        tap.close()


@pytest.mark.slow
def test_the_agent_recovers_from_dropped_connections_and_runs_each_command_once(
    mosquitto: Mosquitto, start_agent: Callable[..., AgentProcess]
) -> None:
    from tests.integration.agent.harness import WireTap
    from tests.support.fault_injection_steps import TcpProxy

    # Given an agent whose connection to the broker goes through a relay that can cut it
    proxy = TcpProxy(mosquitto.config.plain_port or 0)
    tap = WireTap(mosquitto.config.plain_port or 0)
    agent = start_agent("placebot1", "--broker", f"mqtt://127.0.0.1:{proxy.port}")
    try:
        tap.wait_for(lambda m: m.topic == topics.robot_presence("placebot1"), 30)
        recoveries = []
        for drop in range(RESTARTS):
            # When the connection is cut
            connections = proxy.accepted
            assert proxy.drop_all() == 1
            cut_at = time.monotonic()
            # Then a command sent at once is queued by the broker (persistent session) and
            # run exactly once when the agent is back
            command_id = f"after-drop-{drop}"
            tap.publish(topics.robot_cmd("placebot1"), command(command_id, "ping"))
            tap.event("placebot1", "accepted", command_id, timeout_s=RECOVERY_BOUND_S)
            recoveries.append(time.monotonic() - cut_at)
            assert proxy.accepted == connections + 1
            kinds = [e["event"] for e in tap.events("placebot1", command_id)]
            assert kinds.count("accepted") == 1, kinds
        assert agent.process.poll() is None, agent.log()[-2000:]
        print(f"\nlongest recovery after a dropped connection: {max(recoveries):.2f} s "
              f"(all: {', '.join(f'{r:.2f}' for r in recoveries)})")  # fmt: skip
    finally:
        tap.close()
        proxy.close()
