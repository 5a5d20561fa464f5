"""Two real agents coordinate through their events: sequential delivery orders them."""

from __future__ import annotations

from datetime import datetime, timedelta
from typing import TYPE_CHECKING

from tests.integration.agent.harness import command

if TYPE_CHECKING:
    from collections.abc import Callable

    from tests.integration.agent.harness import AgentProcess, ShadowResponder, WireTap


def test_the_second_robot_delivers_only_after_the_first(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    # Given two robots
    start_agent("placebot1")
    start_agent("placebot2")
    for thing in ("placebot1", "placebot2"):
        tap.reported(thing, lambda r: r["connected"] is True)
    # When placebot2 is told to deliver after placebot1, and then placebot1 to deliver
    tap.publish(
        "vahr/robots/placebot2/cmd",
        command("second", "sequential_delivery", {"zone": "B", "after": "placebot1"}),
    )
    waiting = tap.event("placebot2", "waiting", "second")
    assert waiting["reason"] == "waiting for placebot1 to deliver"
    tap.publish("vahr/robots/placebot1/cmd", command("first", "deliver", {"zone": "A"}))
    # Then placebot2 loads only after placebot1 delivered, and both deliver in order
    first_delivered = tap.event("placebot1", "delivered", "first", timeout_s=30)
    second_delivered = tap.event("placebot2", "delivered", "second", timeout_s=30)
    second_loading = next(e for e in tap.events("placebot2", "second") if e["event"] == "arrived")
    assert first_delivered["at"] <= second_loading["at"] < second_delivered["at"]
    state = tap.reported("placebot2", lambda r: (r["last_command"] or {}).get("result") == "done")
    assert state["zone"] == "B"


def test_a_delivery_retained_before_the_robot_started_counts(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    # Given a sequence issued to both robots at once, while placebot2 is still off
    late = command("late", "sequential_delivery", {"zone": "C", "after": "placebot1"})
    start_agent("placebot1")
    tap.reported("placebot1", lambda r: r["connected"] is True)
    tap.publish("vahr/robots/placebot1/cmd", command("early", "deliver", {"zone": "A"}))
    tap.event("placebot1", "delivered", "early", timeout_s=30)
    # When placebot2 starts after placebot1 delivered and only then gets its command
    start_agent("placebot2")
    tap.reported("placebot2", lambda r: r["connected"] is True)
    tap.publish("vahr/robots/placebot2/cmd", late)
    # Then it does not wait (the retained delivered event counts)
    tap.event("placebot2", "delivered", "late", timeout_s=30)
    assert "waiting" not in [e["event"] for e in tap.events("placebot2", "late")]


def test_a_delivery_from_an_earlier_task_does_not_release_a_new_sequence(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess]
) -> None:
    # Given placebot1 delivered for an earlier task
    start_agent("placebot1")
    start_agent("placebot2")
    for thing in ("placebot1", "placebot2"):
        tap.reported(thing, lambda r: r["connected"] is True)
    tap.publish("vahr/robots/placebot1/cmd", command("task2", "deliver", {"zone": "A"}))
    earlier = tap.event("placebot1", "delivered", "task2", timeout_s=30)
    # When a new sequence is issued 3 s after that delivery (past the 2 s clock-skew
    # tolerance, as a next task would be): placebot1 to D, then placebot2 to D
    issued = datetime.fromisoformat(earlier["at"]) + timedelta(seconds=3)
    issued_at = issued.isoformat().replace("+00:00", "Z")
    tap.publish(
        "vahr/robots/placebot2/cmd",
        command(
            "task3b",
            "sequential_delivery",
            {"zone": "D", "after": "placebot1"},
            issued_at=issued_at,
        ),
    )
    # Then placebot2 waits for placebot1's new delivery, not the old one
    tap.event("placebot2", "waiting", "task3b")
    tap.publish(
        "vahr/robots/placebot1/cmd",
        command("task3a", "sequential_delivery", {"zone": "D", "after": None}),
    )
    first = tap.event("placebot1", "delivered", "task3a", timeout_s=30)
    second = tap.event("placebot2", "delivered", "task3b", timeout_s=30)
    assert first["at"] < second["at"]


def test_waiting_for_a_peer_that_never_delivers_times_out_cleanly(
    tap: WireTap, shadows: ShadowResponder, start_agent: Callable[..., AgentProcess], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    config = tmp_path / "agent.yaml"
    config.write_text("executor:\n  sequential_timeout_s: 30\n")
    start_agent("placebot2", "--config", str(config))
    tap.reported("placebot2", lambda r: r["connected"] is True)
    tap.publish(
        "vahr/robots/placebot2/cmd",
        command("lonely", "sequential_delivery", {"zone": "B", "after": "placebot1"}),
    )
    failed = tap.event("placebot2", "failed", "lonely", timeout_s=10)
    assert failed["reason"] == "placebot1 did not deliver within 30 s"
    state = tap.reported("placebot2", lambda r: (r["last_command"] or {}).get("result") == "failed")
    assert state["status"] == "idle" and state["cargo"] is False
    assert state["last_command"]["reason"] == "placebot1 did not deliver within 30 s"
    # and it still serves
    tap.publish("vahr/robots/placebot2/cmd", command("next", "ping"))
    tap.event("placebot2", "done", "next")
