"""Duplicates, restarts and a broker that dies: what the robot does is still right on the wire."""

from __future__ import annotations

import signal
import time
from typing import TYPE_CHECKING

import pytest

from tests.integration.agent.harness import ShadowResponder, command

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.integration.agent.harness import AgentProcess, WireTap
    from vahr.twin.broker import Mosquitto

CMD = "vahr/robots/placebot1/cmd"


def test_the_same_id_twice_runs_once(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    start_agent("placebot1")
    tap.reported("placebot1", lambda r: r["connected"] is True)
    payload = command("twice", "navigate", {"zone": "C"})
    tap.publish(CMD, payload)
    tap.publish(CMD, payload)
    tap.event("placebot1", "done", "twice", timeout_s=20)
    tap.publish(CMD, command("after", "ping"))
    tap.event("placebot1", "done", "after")
    assert [e["event"] for e in tap.events("placebot1", "twice")].count("accepted") == 1


def test_recent_ids_survive_a_restart(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess], tmp_path: Path
) -> None:
    # Given a command the robot ran before it restarted
    first = start_agent("placebot1")
    tap.reported("placebot1", lambda r: r["connected"] is True)
    tap.publish(CMD, command("once", "ping"))
    tap.event("placebot1", "done", "once")
    assert first.stop() == 0
    assert "once" in (tmp_path / "state" / "robots" / "placebot1" / "recent-ids.json").read_text()
    # When the same command is delivered again after the restart (a QoS 1 redelivery)
    start_agent("placebot1")
    mark = tap.mark()
    tap.reported("placebot1", lambda r: r["connected"] is True, after=mark)
    tap.publish(CMD, command("once", "ping"))
    tap.publish(CMD, command("fresh", "ping"))
    # Then only the new one runs
    tap.event("placebot1", "done", "fresh", after=mark)
    assert [e["event"] for e in tap.events("placebot1", "once")] == ["accepted", "done"]


@pytest.mark.slow
def test_a_command_sent_while_the_robot_was_away_arrives_when_it_returns(
    mosquitto: Mosquitto,
    tap: WireTap,
    start_agent: Callable[..., AgentProcess],
) -> None:
    # Given a robot with a persistent session, killed mid-task (a power cut: no clean goodbye)
    shadows = ShadowResponder(mosquitto.config.plain_port or 0)
    agent = start_agent("placebot1", "--sim-speed-factor", "5")
    tap.reported("placebot1", lambda r: r["connected"] is True)
    tap.publish(CMD, command("cut-short", "deliver", {"zone": "A"}))
    tap.event("placebot1", "progress", "cut-short")
    agent.kill()
    # Then its last will marks it offline
    tap.wait_for(
        lambda m: m.topic == "vahr/robots/placebot1/presence" and m.json()["online"] is False
    )
    # When a QoS 1 command is sent while it is away, and the broker restarts (persisting sessions)
    tap.publish(CMD, command("while-away", "navigate", {"zone": "D"}))
    shadows.close()
    tap.close()
    mosquitto.stop()
    mosquitto.start()
    from tests.integration.agent.harness import WireTap as Tap

    tap2 = Tap(mosquitto.config.plain_port or 0)
    shadows = ShadowResponder(mosquitto.config.plain_port or 0)
    try:
        # And the robot comes back
        start_agent("placebot1")
        # Then the delivery it died running is reported failed, with the reason, not re-run
        interrupted = tap2.event("placebot1", "failed", "cut-short", timeout_s=20)
        assert interrupted["reason"].startswith("interrupted: the robot-agent stopped")
        assert [e["event"] for e in tap2.events("placebot1", "cut-short")] == ["failed"]
        # And the command it missed runs
        done = tap2.reported(
            "placebot1",
            lambda r: (
                (r["last_command"] or {}).get("id") == "while-away"
                and r["last_command"]["result"] == "done"
            ),
            timeout_s=20,
        )
        assert done["zone"] == "D"
    finally:
        shadows.close()
        tap2.close()


@pytest.mark.slow
def test_the_broker_killed_mid_task_the_agent_reconnects_and_keeps_serving(
    mosquitto: Mosquitto,
    tmp_path: Path,
    start_agent: Callable[..., AgentProcess],
) -> None:
    from tests.integration.agent.harness import WireTap as Tap

    port = mosquitto.config.plain_port or 0
    tap, shadows = Tap(port), ShadowResponder(port)
    agent = start_agent("placebot1", "--sim-speed-factor", "10")
    tap.reported("placebot1", lambda r: r["connected"] is True)
    tap.publish(CMD, command("through-it", "navigate", {"zone": "A"}))
    tap.event("placebot1", "progress", "through-it")
    # When the broker crashes and comes back a moment later
    shadows.close()
    tap.close()
    mosquitto.kill()
    time.sleep(0.5)
    mosquitto.start()
    tap, shadows = Tap(port), ShadowResponder(port)
    try:
        # Then the robot reconnects, says it is online and reports its state again
        tap.wait_for(
            lambda m: m.topic == "vahr/robots/placebot1/presence" and m.json()["online"] is True,
            timeout_s=20,
        )
        # and the task it was doing finished and is in its shadow
        tap.reported(
            "placebot1",
            lambda r: (
                (r["last_command"] or {}).get("id") == "through-it"
                and r["last_command"]["result"] == "done"
            ),
            timeout_s=20,
        )
        # and it serves a QoS 1 command sent after the restart
        tap.publish(CMD, command("after-crash", "ping"))
        tap.event("placebot1", "done", "after-crash")
        assert agent.stop(signal.SIGTERM) == 0
    finally:
        shadows.close()
        tap.close()


def test_an_agent_that_never_reached_its_broker_stops_cleanly(tmp_path: Path) -> None:
    from tests.integration.agent.harness import AgentProcess
    from vahr.plumbing.ports import free_port

    # Given an agent whose broker is not there, so its first reports are never sent
    agent = AgentProcess(
        "--thing",
        "placebot1",
        "--broker",
        f"mqtt://127.0.0.1:{free_port()}",
        state_dir=tmp_path / "state",
        log_file=tmp_path / "agent.log",
    )
    deadline = time.monotonic() + 15
    while "connection to 127.0.0.1" not in agent.log() and time.monotonic() < deadline:
        time.sleep(0.1)
    # When it is told to stop
    code = agent.stop(signal.SIGTERM, timeout_s=20)
    # Then it exits 0 and the unsent reports are warnings, not asyncio tracebacks
    log = agent.log()
    assert code == 0, log
    assert "publish failed" in log
    assert "Traceback" not in log
