"""A simulated robot on a map: it drives its planned path, never through a cell that is not
free, reports the path in its shadow and its progress and time to arrival along it; it
refuses a closed zone, gives up a task whose zone closes, plans around a closed area, and
leaves one it stands in."""

from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec
import pytest

from tests.support.floor_maps import two_rooms
from tests.unit.agent.conftest import make_executor
from vahr.domain import load_fleet
from vahr.domain.fleet import Point
from vahr.navigation import FleetFloor, load_floor, load_map
from vahr.protocol import new_command

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain import Fleet


@pytest.fixture
def on_map(tmp_path: Path) -> tuple[Fleet, FleetFloor]:
    rooms = two_rooms(tmp_path)
    fleet = load_fleet(rooms.fleet_file)
    # Zone B stands for the west room's lower half (its area)
    area = [Point(0.3, 0.3), Point(4.7, 0.3), Point(4.7, 2.6), Point(0.3, 2.6)]
    zones = [msgspec.structs.replace(z, area=area) if z.id == "B" else z for z in fleet.zones]
    fleet = msgspec.structs.replace(fleet, zones=zones)
    return fleet, FleetFloor(fleet, load_map(rooms.map_file)).check()


async def test_a_robot_drives_its_planned_path_round_the_wall_and_says_so(
    on_map: tuple[Fleet, FleetFloor],
) -> None:
    fleet, floor = on_map
    executor, recorder, backend = make_executor(fleet, thing="left", floor=floor, speed=200)
    command = new_command("navigate", {"zone": "A"}, source="alexa")
    executor.execute(command)
    await recorder.until("arrived", command.id, timeout_s=20)
    # The shadow said the planned path once it planned, from the robot to zone A over the gap
    [path] = [state.path for state in recorder.states if state.path][:1]
    assert path[0] == (4.3, 0.8) and path[-1] == (6.0, 0.8)
    assert max(y for _, y in path) > 3.8
    # and every pose it reported lies on free ground
    grid = floor.grid
    poses = [state.pose for state in recorder.states if state.pose is not None]
    poses += [event.pose for event in recorder.events if event.pose is not None]
    assert poses and all(grid.free[grid.cell(p.x, p.y)] for p in poses)
    # Its progress is the share of the path driven, its ETA what is left at its speed
    progress = [e for e in recorder.events if e.event == "progress"]
    fractions = [e.progress for e in progress]
    assert fractions == sorted(fractions)
    etas = [e.eta_s for e in progress]
    assert all(eta is not None for eta in etas) and etas == sorted(etas, reverse=True)
    # and at the end the shadow holds no path
    assert recorder.states[-1].path is None and recorder.states[-1].zone == "A"
    assert backend.pose == fleet.zone("A").pose


async def test_a_closed_zone_is_refused_and_a_task_into_it_given_up(
    on_map: tuple[Fleet, FleetFloor],
) -> None:
    fleet, floor = on_map
    executor, recorder, _ = make_executor(fleet, thing="right", floor=floor, speed=20)
    executor.close_zones(frozenset({"A"}))
    refused = new_command("navigate", {"zone": "A"}, source="alexa")
    executor.execute(refused)
    assert recorder.first("rejected", refused.id).reason == "zone A is closed"
    # A delivery needs LOADING first: closed, it is refused too
    executor.close_zones(frozenset({"LOADING"}))
    delivery = new_command("deliver", {"zone": "A"}, source="alexa")
    executor.execute(delivery)
    assert recorder.first("rejected", delivery.id).reason == "zone LOADING is closed"
    # A drive under way ends failed when its zone closes
    executor.close_zones(frozenset())
    drive = new_command("navigate", {"zone": "A"}, source="alexa")
    executor.execute(drive)
    await recorder.until("accepted", drive.id)
    executor.close_zones(frozenset({"A"}))
    failed = await recorder.until("failed", drive.id)
    assert failed.reason == "zone A was closed"
    assert executor.state.last_command is not None
    assert (executor.state.last_command.result, executor.state.status) == ("failed", "idle")


async def test_a_robot_in_a_zone_that_closes_leaves_its_area(
    on_map: tuple[Fleet, FleetFloor],
) -> None:
    fleet, floor = on_map
    # Given the left rover idle inside zone B's area
    executor, recorder, backend = make_executor(fleet, thing="left", floor=floor, speed=100)
    assert floor.inside(fleet.zone("B"), backend.pose)
    # When zone B closes
    executor.close_zones(frozenset({"B"}))
    await executor.wait_idle()
    # Then it drove out, reported a path while it did, and stands outside now
    assert not floor.inside(fleet.zone("B"), backend.pose)
    assert any(state.status == "navigating" and state.path for state in recorder.states)
    assert (executor.state.status, executor.state.path) == ("idle", None)


async def test_on_a_drawn_floor_a_robot_leaves_a_closed_zones_circle(fleet: Fleet) -> None:
    # Given the paper's placebot one idle at zone B's pose (a drawn floor, no map)
    executor, _, backend = make_executor(fleet, speed=200)
    executor.execute(new_command("navigate", {"zone": "B"}, source="alexa"))
    await executor.wait_idle()
    assert load_floor(fleet) is None and backend.pose == fleet.zone("B").pose
    # When B closes, it drives out of B's circle
    executor.close_zones(frozenset({"B"}))
    await executor.wait_idle()
    zone = fleet.zone("B")
    assert backend.pose.distance_to(zone.pose) > zone.radius
    assert executor.state.zone is None
