"""Swarm mode: many robots on one connection behave like separate `robot-agent run`s on the wire."""

from __future__ import annotations

import threading
from datetime import UTC, datetime
from typing import TYPE_CHECKING

import pytest

from tests.integration.agent.harness import command
from tests.support.swarm_runner import SwarmThread, swarm_fleet
from vahr.errors import VahrError

if TYPE_CHECKING:
    from tests.integration.agent.harness import ShadowResponder, WireTap
    from vahr.twin.broker import Mosquitto

COUNT = 25


def test_swarm_fleet_names_robots_in_order_and_keeps_the_zones() -> None:
    fleet = swarm_fleet(3, prefix="swarm")
    assert fleet.robot_things == ("swarm0001", "swarm0002", "swarm0003")
    assert fleet.zone_ids == ("LOADING", "A", "B", "C", "D")
    assert all(fleet.zone_at(robot.start) is None for robot in fleet.robots)


def test_a_swarm_that_cannot_be_built_leaves_no_thread_behind() -> None:
    # When a swarm of no robots is started from synchronous code
    with pytest.raises(VahrError, match="at least one robot"):
        SwarmThread(broker="mqtt://127.0.0.1:1", count=0).start()
    # Then its event-loop thread was stopped with it
    assert [t.name for t in threading.enumerate() if t.name == "vahr-swarm"] == []


def test_one_fleet_command_reaches_every_robot_of_the_swarm(
    mosquitto: Mosquitto, tap: WireTap, shadows: ShadowResponder
) -> None:
    with SwarmThread(broker=str(mosquitto.plain_url), count=COUNT, speed_factor=50) as swarm:
        assert swarm.things[0] == "swarm0001" and len(swarm.things) == COUNT
        for thing in swarm.things:
            tap.reported(thing, lambda r: r["connected"] is True)
        # When one fleet-wide publish goes out
        tap.publish("vahr/fleet/cmd", command("fan-out", "ping"))
        # Then every robot acknowledges it in its own shadow and events
        for thing in swarm.things:
            state = tap.reported(thing, lambda r: (r["last_command"] or {}).get("id") == "fan-out")
            assert state["last_command"]["action"] == "ping"
            tap.event(thing, "done", "fan-out")
        # and a command to one robot moves only that robot
        tap.publish("vahr/robots/swarm0007/cmd", command("solo", "navigate", {"zone": "C"}))
        done = tap.reported(
            "swarm0007",
            lambda r: (
                r["last_command"]
                == {
                    "id": "solo",
                    "action": "navigate",
                    "result": "done",
                    "reason": None,
                    "zone": "C",
                }
            ),
            timeout_s=20,
        )
        assert done["zone"] == "C"
        assert swarm.state("swarm0007").zone == "C"
        assert swarm.state("swarm0008").zone is None
        mark = tap.mark()
    # When the swarm stops, every robot reports offline
    for thing in swarm.things:
        tap.wait_for(
            lambda m, thing=thing: (
                m.topic == f"vahr/robots/{thing}/presence" and m.json()["online"] is False
            ),
            after=mark,
        )


def test_swarm_robots_coordinate_a_sequential_delivery(
    mosquitto: Mosquitto, tap: WireTap, shadows: ShadowResponder
) -> None:
    with SwarmThread(broker=str(mosquitto.plain_url), count=2, speed_factor=50) as swarm:
        first, second = swarm.things
        tap.reported(second, lambda r: r["connected"] is True)
        tap.publish(
            f"vahr/robots/{second}/cmd",
            command("s2", "sequential_delivery", {"zone": "B", "after": first}),
        )
        tap.event(second, "waiting", "s2")
        tap.publish(f"vahr/robots/{first}/cmd", command("s1", "deliver", {"zone": "A"}))
        delivered_first = tap.event(first, "delivered", "s1", timeout_s=30)
        delivered_second = tap.event(second, "delivered", "s2", timeout_s=30)
        assert delivered_first["at"] < delivered_second["at"]


def test_a_swarm_robot_hears_a_peer_outside_its_swarm_deliver(
    mosquitto: Mosquitto, tap: WireTap, shadows: ShadowResponder
) -> None:
    # Given a swarm running only the second robot of a two-robot fleet, waiting for the
    # first, which runs elsewhere (another connection)
    with SwarmThread(
        broker=str(mosquitto.plain_url), count=2, things=["swarm0002"], speed_factor=50
    ) as swarm:
        assert swarm.things == ["swarm0002"]
        tap.reported("swarm0002", lambda r: r["connected"] is True)
        tap.publish(
            "vahr/robots/swarm0002/cmd",
            command("w2", "sequential_delivery", {"zone": "B", "after": "swarm0001"}),
        )
        tap.event("swarm0002", "waiting", "w2")
        # When the first robot says it delivered
        delivered = {
            "event": "delivered",
            "thing": "swarm0001",
            "at": datetime.now(UTC).isoformat().replace("+00:00", "Z"),
            "command_id": "w1",
            "action": "deliver",
            "zone": "A",
        }
        tap.publish("vahr/robots/swarm0001/events", delivered)
        # Then the second goes on and delivers in its turn
        tap.event("swarm0002", "delivered", "w2", timeout_s=30)


def test_a_bad_fleet_command_is_rejected_by_every_robot_with_the_reason(
    mosquitto: Mosquitto, tap: WireTap, shadows: ShadowResponder
) -> None:
    with SwarmThread(broker=str(mosquitto.plain_url), count=COUNT, speed_factor=50) as swarm:
        for thing in swarm.things:
            tap.reported(thing, lambda r: r["connected"] is True)
        # When one fleet-wide command names a zone the fleet does not have, then a good one
        tap.publish("vahr/fleet/cmd", command("bad-zone", "navigate", {"zone": "Z"}))
        tap.publish("vahr/fleet/cmd", command("good-ping", "ping"))
        # Then every robot rejects the first with the reason, and takes the second
        for thing in swarm.things:
            rejected = tap.event(thing, "rejected", "bad-zone")
            assert "params.zone" in rejected["reason"], rejected
            state = tap.reported(
                thing, lambda r: (r["last_command"] or {}).get("id") == "good-ping"
            )
            assert state["last_command"]["result"] == "done"
