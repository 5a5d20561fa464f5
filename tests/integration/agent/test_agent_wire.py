"""A real `robot-agent run` on a real mosquitto: what appears on the wire."""

from __future__ import annotations

import signal
from typing import TYPE_CHECKING

from tests.integration.agent.harness import command

if TYPE_CHECKING:
    from collections.abc import Callable

    from tests.integration.agent.harness import AgentProcess, ShadowResponder, WireTap

CMD = "vahr/robots/placebot1/cmd"


def online(tap: WireTap, thing: str = "placebot1", after: int = 0) -> None:
    tap.wait_for(
        lambda m: m.topic == f"vahr/robots/{thing}/presence" and m.json()["online"] is True,
        after=after,
    )


def test_a_command_reaches_the_agent_and_state_and_events_appear_on_the_wire(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    # Given a running robot
    agent = start_agent("placebot1")
    online(tap)
    first = tap.reported("placebot1", lambda r: r["connected"] is True)
    assert first["status"] == "idle" and first["last_command"] is None
    # When the console sends it to zone B
    tap.publish(CMD, command("nav-1", "navigate", {"zone": "B"}))
    # Then it acknowledges in the shadow, drives, and arrives
    accepted = tap.reported("placebot1", lambda r: (r["last_command"] or {}).get("id") == "nav-1")
    assert accepted["last_command"]["result"] == "accepted"
    done = tap.reported(
        "placebot1", lambda r: (r["last_command"] or {}).get("result") == "done", timeout_s=20
    )
    assert (done["status"], done["zone"], done["last_command"]["id"]) == ("idle", "B", "nav-1")
    tap.event("placebot1", "done", "nav-1")
    kinds = [e["event"] for e in tap.events("placebot1", "nav-1")]
    assert kinds[0] == "accepted" and kinds[-2:] == ["arrived", "done"] and "progress" in kinds
    # and the shadow service holds the same state
    shadows.document("placebot1", lambda d: d.get("reported", {}).get("zone") == "B")
    # When it is asked to stop running
    mark = tap.mark()
    assert agent.stop(signal.SIGTERM) == 0
    # Then it reported its final state and went offline cleanly
    final = tap.reported("placebot1", lambda r: r["connected"] is False, after=mark)
    assert final["zone"] == "B"
    offline = tap.wait_for(
        lambda m: m.topic == "vahr/robots/placebot1/presence" and m.json()["online"] is False,
        after=mark,
    )
    assert offline.json()["online"] is False
    assert (tap.retained("vahr/robots/placebot1/presence") or {}).get("online") is False
    # and its log has one line per event
    log = agent.log()
    assert "placebot1: accepted navigate nav-1" in log
    assert "placebot1: arrived navigate nav-1 zone=B" in log
    assert log.count("placebot1: done navigate nav-1") == 1


def test_the_fleet_topic_reaches_every_robot(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    start_agent("placebot1")
    start_agent("placebot2")
    online(tap, "placebot1")
    online(tap, "placebot2")
    tap.reported("placebot2", lambda r: r["connected"] is True)
    tap.publish("vahr/fleet/cmd", command("all-1", "ping"))
    for thing in ("placebot1", "placebot2"):
        state = tap.reported(thing, lambda r: (r["last_command"] or {}).get("id") == "all-1")
        assert state["last_command"]["action"] == "ping"
        assert tap.event(thing, "done", "all-1")["thing"] == thing


def test_a_command_written_as_desired_state_runs_and_desired_is_cleared(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    start_agent("placebot1")
    online(tap)
    tap.reported("placebot1", lambda r: r["connected"] is True)
    shadows.set_desired("placebot1", {"command": command("desired-1", "navigate", {"zone": "A"})})
    done = tap.reported(
        "placebot1", lambda r: (r["last_command"] or {}).get("result") == "done", timeout_s=20
    )
    assert (done["zone"], done["last_command"]["id"]) == ("A", "desired-1")
    tap.wait_for(
        lambda m: (
            m.topic == "$aws/things/placebot1/shadow/update"
            and m.json() == {"state": {"desired": None}}
        )
    )
    shadows.document("placebot1", lambda d: "desired" not in d)


def test_desired_state_written_while_offline_is_applied_on_connect(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    # Given a command left in desired state before the robot comes online
    shadows.set_desired("placebot2", {"command": command("while-away", "navigate", {"zone": "D"})})
    # When the robot starts
    start_agent("placebot2")
    # Then it reads its shadow, runs the command and clears desired
    done = tap.reported(
        "placebot2", lambda r: (r["last_command"] or {}).get("result") == "done", timeout_s=20
    )
    assert (done["zone"], done["last_command"]["id"]) == ("D", "while-away")
    tap.wait_for(
        lambda m: (
            m.topic == "$aws/things/placebot2/shadow/update"
            and m.json() == {"state": {"desired": None}}
        )
    )


def test_a_version_conflict_is_answered_by_reading_and_reporting_again(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    shadows.conflicts_to_inject = 1
    start_agent("placebot1")
    rejected = tap.wait_for(lambda m: m.topic == "$aws/things/placebot1/shadow/update/rejected")
    assert rejected.json()["code"] == 409
    # The agent re-reads (get) and sends its state again, which is then accepted.
    after = tap.messages.index(rejected)
    tap.wait_for(lambda m: m.topic == "$aws/things/placebot1/shadow/get", after=after)
    tap.reported("placebot1", lambda r: r["connected"] is True, after=after)
    tap.wait_for(lambda m: m.topic == "$aws/things/placebot1/shadow/update/accepted", after=after)
    shadows.document("placebot1", lambda d: d.get("reported", {}).get("connected") is True)


def test_stop_preempts_a_delivery(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    start_agent("placebot1", "--sim-speed-factor", "5")
    online(tap)
    tap.publish(CMD, command("long", "deliver", {"zone": "A"}))
    tap.event("placebot1", "progress", "long")
    tap.publish(CMD, command("halt", "stop"))
    cancelled = tap.event("placebot1", "cancelled", "long")
    assert cancelled["reason"] == "preempted by stop halt"
    tap.event("placebot1", "stopped", "halt")
    state = tap.reported(
        "placebot1",
        lambda r: (
            (r["last_command"] or {}).get("id") == "halt" and r["last_command"]["result"] == "done"
        ),
    )
    assert state["status"] == "stopped" and state["task"] is None
    assert "delivered" not in [e["event"] for e in tap.events("placebot1", "long")]


def test_plaintext_to_a_non_loopback_host_is_refused_in_one_line(
    start_agent: Callable[..., AgentProcess], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    import subprocess

    from tests.integration.agent.harness import AGENT

    result = subprocess.run(
        [str(AGENT), "run", "--thing", "placebot1", "--broker", "mqtt://example.com:1883"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "robot-agent run: error: --broker 'mqtt://example.com:1883': plaintext MQTT is allowed only to a loopback broker; use --endpoint with --cert, --key and --ca for any other host"
    ]


def test_sigint_stops_the_agent_cleanly_too(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    agent = start_agent("placebot2")
    tap.reported("placebot2", lambda r: r["connected"] is True)
    tap.publish("vahr/robots/placebot2/cmd", command("cut", "navigate", {"zone": "A"}))
    tap.event("placebot2", "accepted", "cut")
    mark = tap.mark()
    assert agent.stop(signal.SIGINT) == 0
    cancelled = tap.event("placebot2", "cancelled", "cut", after=mark)
    assert cancelled["reason"] == "the agent is shutting down"
    final = tap.reported("placebot2", lambda r: r["connected"] is False, after=mark)
    assert final["last_command"] == {
        "id": "cut",
        "action": "navigate",
        "result": "cancelled",
        "reason": "the agent is shutting down",
        "zone": "A",
    }
    assert final["status"] == "stopped" and final["task"] is None


def test_a_robot_that_gets_stuck_says_so_in_its_shadow(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    # Given a robot whose way to zone D is blocked half way
    config = tmp_path / "stuck.yaml"
    config.write_text("sim:\n  stuck_zones: [D]\nexecutor:\n  stuck_after_s: 5\n")
    start_agent("placebot1", "--config", str(config))
    tap.reported("placebot1", lambda r: r["connected"] is True)
    # When it is sent there
    tap.publish(CMD, command("blocked", "navigate", {"zone": "D"}))
    # Then it reports stuck, and the command failed with the reason
    stuck = tap.event("placebot1", "stuck", "blocked", timeout_s=20)
    assert stuck["reason"] == "no progress towards D for 5 s"
    state = tap.reported("placebot1", lambda r: (r["last_command"] or {}).get("result") == "failed")
    assert state["status"] == "stuck"
    assert state["last_command"]["reason"] == "stuck: no progress towards D for 5 s"


def test_weather_delivery_talks_to_the_assistant_and_delivers_on_the_wire(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    # Given a robot whose voice reaches an assistant that answers "rainy"
    voice = "tests.unit.agent.test_agent_weather_delivery:scripted_rainy_assistant"
    start_agent("placebot1", "--voice", voice)
    tap.reported("placebot1", lambda r: r["connected"] is True)
    # When it is asked to do the weather delivery
    tap.publish(CMD, command("weather", "weather_delivery"))
    # Then the conversation is on the wire, and it delivers to C
    delivered = tap.event("placebot1", "delivered", "weather", timeout_s=30)
    assert delivered["zone"] == "C"
    said = [e["text"] for e in tap.events("placebot1", "weather") if e["event"] == "said"]
    assert said == [
        "Alexa, ask robot fleet what the weather is",
        "Thank you. It is rainy, so I am delivering to zone C.",
    ]
    heard = tap.event("placebot1", "heard", "weather")
    assert heard["text"] == "The weather is rainy, placebot1."
    interpreted = tap.event("placebot1", "interpreted", "weather")
    assert (interpreted["intent"], interpreted["confidence"]) == ("rainy", 0.9)


def test_weather_delivery_without_a_voice_fails_with_the_reason(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    start_agent("placebot2")
    tap.reported("placebot2", lambda r: r["connected"] is True)
    tap.publish("vahr/robots/placebot2/cmd", command("no-voice", "weather_delivery"))
    state = tap.reported("placebot2", lambda r: (r["last_command"] or {}).get("result") == "failed")
    assert state["last_command"] == {
        "id": "no-voice",
        "action": "weather_delivery",
        "result": "failed",
        "reason": "voice not configured",
        "zone": None,
    }
