"""Dispatch on a map and with zones closed: the cost is the planned path's length, read from
one distance field per zone (`vahr.navigation` locally, the bundled fields in the Lambda,
which agree); a closed zone is refused, its queued tasks wait and go when it opens, and a
task whose robot gave it up because its zone closed waits again."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from infra.floor_distances import write_distances
from tests.support.floor_maps import two_rooms
from vahr.dispatch import Dispatcher, DispatchError, Order, RobotState, Task, rank, task_cost
from vahr.dispatch.grid_routes import DistancesError, GridRoutes, floor_routes
from vahr.domain import load_fleet
from vahr.local.task_store import SqliteTaskStore
from vahr.navigation import load_floor

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.protocol import Command, ZoneClosures


@pytest.fixture
def rooms_fleet(tmp_path: Path) -> Fleet:
    return load_fleet(two_rooms(tmp_path).fleet_file)


class Robots:
    """The `Candidates` port over the fleet's robots, idle at their starts."""

    def __init__(self, fleet: Fleet) -> None:
        self.states = {
            r.thing: RobotState(thing=r.thing, status="idle", pose=r.start) for r in fleet.robots
        }

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        return [s for s in self.states.values() if zone is None or s.zone == zone]

    def state(self, thing: str) -> RobotState | None:
        return self.states.get(thing)


def probe(zone: str, pickup: str | None = None) -> Task:
    kind = "deliver" if pickup else "navigate"
    return Task(id="t", request="r", kind=kind, zone=zone, pickup=pickup, created_at="2026")


def test_the_robot_nearer_by_path_ranks_first_on_both_hosts(
    rooms_fleet: Fleet, tmp_path: Path
) -> None:
    floor = load_floor(rooms_fleet)
    assert floor is not None
    robots = Robots(rooms_fleet).available()
    # In a straight line the left rover is nearer zone A; by path the right one is
    straight = rank(rooms_fleet, probe("A"), robots)
    local = rank(rooms_fleet, probe("A"), robots, routes=floor.routes())
    assert [r.thing for r in straight] == ["left", "right"]
    assert [r.thing for r in local] == ["right", "left"]
    # The Lambda's fields, written for the bundle and read without numpy, agree
    write_distances(rooms_fleet, tmp_path / "fleet-distances.bin")
    grid = floor_routes(rooms_fleet, str(tmp_path / "fleet-distances.bin"))
    assert [r.thing for r in rank(rooms_fleet, probe("A"), robots, routes=grid)] == [
        "right",
        "left",
    ]
    for robot in rooms_fleet.robots:
        for task in (probe("A"), probe("A", pickup="LOADING"), probe("B", pickup="LOADING")):
            near = task_cost(rooms_fleet, robot.start, task, floor.routes())
            far = task_cost(rooms_fleet, robot.start, task, grid)
            assert far == pytest.approx(near, abs=0.05), (robot.thing, task.zone)


def test_distances_for_another_fleet_are_refused(rooms_fleet: Fleet, tmp_path: Path) -> None:
    # Given the distances of the two rooms' fleet
    path = tmp_path / "fleet-distances.bin"
    write_distances(rooms_fleet, path)
    # When zone A has moved since, or no file is there, the dispatcher says so
    (tmp_path / "moved").mkdir()
    moved = two_rooms(tmp_path / "moved").fleet_file
    moved.write_text(moved.read_text().replace("{x: 6.0, y: 0.8, theta: 0.0}", "{x: 7.0, y: 0.8}"))
    with pytest.raises(DistancesError, match="made for another fleet or map"):
        GridRoutes.read(str(path), load_fleet(moved))
    with pytest.raises(DistancesError, match="cannot read"):
        floor_routes(rooms_fleet, str(tmp_path / "none.bin"))


@pytest.fixture
def dispatcher(
    rooms_fleet: Fleet, tmp_path: Path
) -> Iterator[tuple[Dispatcher, list[str], list[ZoneClosures]]]:
    store = SqliteTaskStore.in_state_dir(tmp_path)
    sent: list[str] = []
    told: list[ZoneClosures] = []
    floor = load_floor(rooms_fleet)
    assert floor is not None

    def publish(thing: str, command: Command) -> None:
        sent.append(thing)

    yield (
        Dispatcher(
            fleet=rooms_fleet,
            store=store,
            candidates=Robots(rooms_fleet),
            publish=publish,
            routes=floor.routes,
            publish_closures=told.append,
        ),
        sent,
        told,
    )
    store.close()


def test_a_closed_zone_takes_no_order_and_its_queue_waits_until_it_opens(
    dispatcher: tuple[Dispatcher, list[str], list[ZoneClosures]],
) -> None:
    core, sent, told = dispatcher
    robots = core.candidates
    assert isinstance(robots, Robots)
    # Given both robots busy on tasks, and a third task to zone B queued
    core.submit(Order(zone="A"))
    core.submit(Order(zone="A"))
    queued = core.submit(Order(zone="B")).queued
    assert len(queued) == 1 and len(sent) == 2
    # When zone B closes
    change = core.set_zone("B", closed=True)
    # Then the robots are told, the queued task is said to wait, and nothing is sent
    assert (change.closed, change.changed, [t.id for t in change.waiting]) == (
        True,
        True,
        [queued[0].id],
    )
    assert told[-1].closed == ["B"] and core.closed_zones() == ["B"]
    assert core.set_zone("B", closed=True).changed is False
    # and a new order to it is refused, nothing stored
    with pytest.raises(DispatchError) as refused:
        core.submit(Order(zone="B"))
    assert refused.value.code == "zone_closed"
    assert [t.zone for t in core.pending()] == ["B"]
    # When a robot is freed, it does not take the task into the closed zone
    held = {t.thing: t for t in core.store.active()}
    core.store.finish(held["left"].id, outcome="done")
    assert core.robot_freed("left") is None
    # When zone B opens, the task that waited goes to the free robot
    opened = core.set_zone("B", closed=False)
    assert (opened.closed, opened.changed) == (False, True)
    assert [t.id for t in opened.given] == [queued[0].id] and sent[-1] == "left"
    assert told[-1].closed == []
    with pytest.raises(DispatchError) as unknown:
        core.set_zone("Z", closed=True)
    assert unknown.value.code == "unknown_zone"
