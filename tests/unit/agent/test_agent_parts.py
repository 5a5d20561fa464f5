"""The executor's small parts: recent ids on disk, peer deliveries, topic matching, the sim."""

from __future__ import annotations

import asyncio
import json
import time
from datetime import timedelta
from typing import TYPE_CHECKING

import pytest

from robot_agent.backends.port import NavigationFailed, Progress
from robot_agent.backends.sim import SimBackend
from robot_agent.clock import ScaledClock
from robot_agent.config import SimSettings
from robot_agent.core.in_flight import InFlight
from robot_agent.core.peers import PeerDeliveries
from robot_agent.core.recent_ids import RecentIds
from vahr.domain import Pose
from vahr.protocol import utc_now
from vahr.protocol.link import topic_matches

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain import Fleet


def test_recent_ids_remember_across_instances_and_forget_the_oldest(tmp_path: Path) -> None:
    path = tmp_path / "robots" / "placebot1" / "recent-ids.json"
    ids = RecentIds(path, capacity=3)
    assert ids.add("a") and ids.add("b") and not ids.add("a")
    reopened = RecentIds(path, capacity=3)
    assert "a" in reopened and "b" in reopened
    for command_id in ("c", "d"):
        reopened.add(command_id)
    assert "a" not in RecentIds(path, capacity=3)
    assert json.loads(path.read_text()) == ["b", "c", "d"]


def test_a_torn_recent_id_file_does_not_stop_the_robot(tmp_path: Path) -> None:
    path = tmp_path / "recent-ids.json"
    path.write_text('["a", "b"')
    ids = RecentIds(path)
    assert len(ids) == 0 and ids.add("a")


def test_a_recent_id_file_that_cannot_be_written_does_not_lose_the_command(
    tmp_path: Path,
) -> None:
    # Given a state directory that cannot be created (a file stands in its place)
    (tmp_path / "robots").write_text("not a directory")
    ids = RecentIds(tmp_path / "robots" / "recent-ids.json")
    # When a command id arrives, then it is new (it runs), and a redelivery is a duplicate
    assert ids.add("a") is True
    assert ids.add("a") is False


def test_the_running_command_survives_a_crash_on_disk_and_is_forgotten_when_it_ends(
    tmp_path: Path,
) -> None:
    path = tmp_path / "robots" / "placebot1" / "in-flight.json"
    # Given a robot running d1 that dies (its InFlight is never told the task ended)
    InFlight(path).start("d1", "deliver")
    # Then the next run finds d1 left over
    assert InFlight(path).left_over() == [("d1", "deliver")]
    # And a command taken while another runs is kept beside it until each one ends
    running = InFlight(path)
    running.start("d1", "deliver")
    running.start("n1", "navigate")
    assert InFlight(path).left_over() == [("d1", "deliver"), ("n1", "navigate")]
    running.end("d1")
    assert InFlight(path).left_over() == [("n1", "navigate")]
    running.end("n1")
    assert InFlight(path).left_over() == [] and not path.exists()


def test_the_one_command_file_of_earlier_versions_is_still_read(tmp_path: Path) -> None:
    path = tmp_path / "in-flight.json"
    path.write_text('{"id": "d1", "action": "deliver"}')
    assert InFlight(path).left_over() == [("d1", "deliver")]


def test_a_torn_in_flight_file_does_not_stop_the_robot(tmp_path: Path) -> None:
    path = tmp_path / "in-flight.json"
    path.write_text('{"id": "d1"')
    assert InFlight(path).left_over() == []


def test_only_a_peer_delivery_after_the_command_was_issued_counts() -> None:
    # Given a command issued now
    peers = PeerDeliveries()
    issued = utc_now()
    # When the peer's last delivery was for an earlier task, then it does not count
    peers.record("placebot1", issued - timedelta(seconds=30))
    assert peers.delivered_since("placebot1", issued, skew_s=2) is None
    # When its clock runs a second behind the sender's, then a fresh delivery still counts
    peers.record("placebot1", issued - timedelta(seconds=1))
    assert peers.delivered_since("placebot1", issued, skew_s=2) is not None
    # And another peer's delivery never counts for this one
    assert peers.delivered_since("placebot2", issued, skew_s=2) is None


async def test_a_waiter_is_woken_by_the_next_delivery() -> None:
    peers = PeerDeliveries()
    waiter = peers.next_delivery("placebot1")
    at = utc_now()
    peers.record("placebot1", at)
    assert await asyncio.wait_for(waiter, 1) == at
    # An older event arriving late does not move the latest delivery back.
    peers.record("placebot1", at - timedelta(minutes=5))
    assert peers.latest("placebot1") == at


@pytest.mark.parametrize(
    ("topic_filter", "topic", "matches"),
    [
        ("vahr/robots/+/events", "vahr/robots/placebot1/events", True),
        ("vahr/robots/+/events", "vahr/robots/placebot1/cmd", False),
        ("vahr/#", "vahr/fleet/cmd", True),
        ("#", "$aws/things/placebot1/shadow/update", False),
        ("$aws/things/placebot1/shadow/#", "$aws/things/placebot1/shadow/update/delta", True),
        ("vahr/fleet/cmd", "vahr/fleet/cmd/extra", False),
        ("vahr/robots/+", "vahr/robots", False),
    ],
)
def test_topic_matching_follows_mqtt(topic_filter: str, topic: str, matches: bool) -> None:
    assert topic_matches(topic_filter, topic) is matches


async def test_the_simulator_takes_distance_over_speed_in_simulated_time(fleet: Fleet) -> None:
    clock = ScaledClock(200)
    start = Pose(0.0, 4.0, 0.0)
    sim = SimBackend(
        start=start, clock=clock, settings=SimSettings(speed_mps=1.0, turn_rate_rps=2.0)
    )
    zone = fleet.zone("B")  # (9, 5): 9.06 m away, a small turn
    seen: list[Progress] = []
    began = clock.monotonic()
    await sim.go_to(zone, seen.append)
    elapsed = clock.monotonic() - began
    assert 9.0 <= elapsed <= 9.0 + 3.0  # driving plus turning, within scheduling slack
    assert sim.pose == zone.pose
    fractions = [p.fraction for p in seen]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0


async def test_an_injected_failure_aborts_half_way(fleet: Fleet) -> None:
    sim = SimBackend(start=fleet.robot("placebot1").start, clock=ScaledClock(500))
    sim.inject_failure("a person stands in the corridor")
    with pytest.raises(NavigationFailed, match="a person stands in the corridor"):
        await sim.go_to(fleet.zone("A"), lambda progress: None)
    # The fault was for one goal only.
    await sim.go_to(fleet.zone("A"), lambda progress: None)
    assert sim.pose == fleet.zone("A").pose


async def test_a_scaled_clock_sleeps_less_on_the_wall() -> None:
    clock = ScaledClock(100)
    began = time.monotonic()
    await clock.sleep(5)
    assert time.monotonic() - began < 1.0
    with pytest.raises(ValueError, match="speed_factor"):
        ScaledClock(0)


def test_nagle_is_disabled_only_on_connections_to_the_broker_port() -> None:
    import socket

    from robot_agent.link.mqtt5 import disable_nagle

    with (
        socket.create_server(("127.0.0.1", 0)) as server,
        socket.create_server(("127.0.0.1", 0)) as other,
    ):
        to_broker = socket.create_connection(server.getsockname())
        elsewhere = socket.create_connection(other.getsockname())
        with to_broker, elsewhere:
            assert disable_nagle(server.getsockname()[1]) == 1
            assert to_broker.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) == 1
            assert elsewhere.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) == 0
            # Blocking mode is the socket owner's business and stays as it was.
            assert to_broker.getblocking() and server.getblocking()
