"""Bad payloads are rejected with a reason, on the wire and in the shadow, and the agent
keeps serving (docs/protocol.md: unknown actions, missing or bad params, oversize, non-JSON)."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import pytest

from tests.integration.agent.harness import command

if TYPE_CHECKING:
    from collections.abc import Callable

    from tests.integration.agent.harness import AgentProcess, ShadowResponder, WireTap


def ok(**changes: Any) -> bytes:
    """A valid navigate command with some fields changed (None removes a field)."""
    body = command("bad", "navigate", {"zone": "A"})
    for key, value in changes.items():
        if value is None:
            body.pop(key, None)
        else:
            body[key] = value
    return json.dumps(body).encode()


# (what is wrong, payload, the field the reason must start with)
BAD_PAYLOADS: list[tuple[str, bytes, str]] = [
    ("empty payload", b"", "payload"),
    ("plain text", b"drive to zone a", "payload"),
    ("truncated JSON", b'{"id": "x", "action": "navig', "payload"),
    ("JSON array", b'[{"id": "x"}]', "payload"),
    ("JSON number", b"42", "payload"),
    ("JSON null", b"null", "payload"),
    ("JSON string", b'"navigate"', "payload"),
    ("invalid UTF-8", b'{"id": "\xff\xfe"}', "payload"),
    ("over 8 KB", ok(source="console:" + "x" * 9000), "payload"),
    ("empty object", b"{}", "action"),
    ("id missing", ok(id=None), "id"),
    ("id empty", ok(id=""), "id"),
    ("id over 64 chars", ok(id="x" * 65), "id"),
    ("id a number", ok(id=7), "id"),
    ("action unknown", ok(action="fly"), "action"),
    ("action missing", ok(action=None), "action"),
    ("action a number", ok(action=3), "action"),
    ("params missing", ok(params=None), "params"),
    ("params a list", ok(params=["A"]), "params"),
    ("zone missing", ok(params={}), "params.zone"),
    ("zone unknown", ok(params={"zone": "Z"}), "params.zone"),
    ("zone a number", ok(params={"zone": 1}), "params.zone"),
    ("zone empty", ok(params={"zone": ""}), "params.zone"),
    ("zone too long", ok(params={"zone": "A" * 40}), "params.zone"),
    ("extra param", ok(params={"zone": "A", "speed": 9}), "params.speed"),
    ("unknown field", ok(priority="high"), "priority"),
    ("issued_at missing", ok(issued_at=None), "issued_at"),
    ("issued_at not a time", ok(issued_at="yesterday"), "issued_at"),
    ("issued_at without zone", ok(issued_at="2026-11-22T10:00:00"), "issued_at"),
    ("source missing", ok(source=None), "source"),
    ("source malformed", ok(source="Alexa!"), "source"),
    ("stop with params", json.dumps(command("bad", "stop", {"zone": "A"})).encode(), "params.zone"),
    ("ping with params", json.dumps(command("bad", "ping", {"x": 1})).encode(), "params.x"),
    (
        "sequential without after",
        json.dumps(command("bad", "sequential_delivery", {"zone": "B"})).encode(),
        "params.after",
    ),
    (
        "sequential after a stranger",
        json.dumps(
            command("bad", "sequential_delivery", {"zone": "B", "after": "robot9"})
        ).encode(),
        "params.after",
    ),
    (
        "sequential after itself",
        json.dumps(
            command("bad", "sequential_delivery", {"zone": "B", "after": "placebot1"})
        ).encode(),
        "params.after",
    ),
    (
        "deliver to an unknown zone",
        json.dumps(command("bad", "deliver", {"zone": "E"})).encode(),
        "params.zone",
    ),
]


def test_there_are_at_least_thirty_kinds() -> None:
    assert len({name for name, _, _ in BAD_PAYLOADS}) >= 30


@pytest.mark.slow
def test_every_bad_payload_is_rejected_with_a_reason_and_the_agent_keeps_serving(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    # Given a running robot
    agent = start_agent("placebot1")
    tap.reported("placebot1", lambda r: r["connected"] is True)
    reasons: dict[str, str] = {}
    for name, payload, field in BAD_PAYLOADS:
        mark = tap.mark()
        # When a bad payload arrives on its command topic
        tap.publish("vahr/robots/placebot1/cmd", payload)
        # Then a rejected event names the field and the reason
        rejected = tap.event("placebot1", "rejected", after=mark, timeout_s=5)
        reason = rejected["reason"]
        assert reason.startswith(field), f"{name}: {reason}"
        assert ": " in reason, f"{name}: {reason}"
        reasons[name] = reason
        # and the shadow says the same
        state = tap.reported(
            "placebot1",
            lambda r, reason=reason: (r["last_command"] or {}).get("reason") == reason,
            after=mark,
        )
        assert state["last_command"]["result"] == "rejected"
        assert state["status"] == "idle"
    # Every kind got its own words, not one catch-all message.
    assert len(set(reasons.values())) >= 30
    # And the robot still serves good commands
    tap.publish("vahr/robots/placebot1/cmd", command("still-here", "ping"))
    tap.event("placebot1", "done", "still-here")
    assert agent.process.poll() is None


def test_a_rejected_command_keeps_its_id_in_the_shadow_so_the_skill_can_tell(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    start_agent("placebot1")
    tap.reported("placebot1", lambda r: r["connected"] is True)
    tap.publish("vahr/robots/placebot1/cmd", command("to-nowhere", "navigate", {"zone": "Q"}))
    state = tap.reported("placebot1", lambda r: (r["last_command"] or {}).get("id") == "to-nowhere")
    assert state["last_command"] == {
        "id": "to-nowhere",
        "action": "navigate",
        "result": "rejected",
        "reason": "params.zone: 'Q' is not a zone; zones are LOADING, A, B, C, D",
        "zone": None,
    }
