"""Paths on a map: never through a cell that is not free, inflated by the robot's radius,
shortened to straight legs; one search from a goal measures every robot; a closed zone's
area is driven around and left; a fleet that cannot be on its map is one line."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import msgspec
import numpy as np
import pytest

from tests.support.floor_maps import FREE, OCCUPIED, two_rooms, write_map
from vahr.domain import load_fleet
from vahr.domain.fleet import Point
from vahr.navigation import FleetFloor, MapError, load_floor, load_map

if TYPE_CHECKING:
    from pathlib import Path

    from tests.support.floor_maps import TwoRooms
    from vahr.navigation import Planner, Route


@pytest.fixture
def rooms(tmp_path: Path) -> TwoRooms:
    return two_rooms(tmp_path)


@pytest.fixture
def floor(rooms: TwoRooms) -> FleetFloor:
    found = load_floor(load_fleet(rooms.fleet_file))
    assert found is not None
    return found


def on_drivable_cells(planner: Planner, route: Route) -> bool:
    """Every point of every leg, sampled a tenth of a cell apart, is on a drivable cell."""
    grid = planner.grid
    for (ax, ay), (bx, by) in zip(route.points, route.points[1:], strict=False):
        steps = max(2, math.ceil(math.hypot(bx - ax, by - ay) / grid.resolution * 10))
        for t in np.linspace(0.0, 1.0, steps):
            cell = grid.cell(ax + (bx - ax) * t, ay + (by - ay) * t)
            if cell is None or not planner.drivable[cell]:
                return False
    return True


def test_the_way_round_the_wall_goes_through_the_gap_in_few_straight_legs(
    floor: FleetFloor, rooms: TwoRooms
) -> None:
    left, zone_a = floor.fleet.robot("left").start, floor.fleet.zone("A").pose
    route = floor.open.plan((left.x, left.y), (zone_a.x, zone_a.y))
    assert route is not None
    # It starts at the robot, ends at the zone, and passes above the wall's top
    assert route.points[0] == (left.x, left.y) and route.points[-1] == (zone_a.x, zone_a.y)
    assert max(y for _, y in route.points) > rooms.gap_bottom
    # never leaving the drivable cells (the wall and its margin of the robot's radius)
    assert on_drivable_cells(floor.open, route)
    # in a handful of legs, not a staircase of cells, and far longer than the straight line
    assert len(route.points) <= 8
    assert route.length > 4 * left.distance_to(zone_a)
    assert route.length == pytest.approx(
        sum(math.dist(a, b) for a, b in zip(route.points, route.points[1:], strict=False))
    )


def test_one_search_from_the_zone_ranks_robots_by_path_not_by_straight_line(
    floor: FleetFloor,
) -> None:
    zone_a = floor.fleet.zone("A").pose
    field = floor.open.field(zone_a.x, zone_a.y)
    left, right = floor.fleet.robot("left").start, floor.fleet.robot("right").start
    # The left robot is nearer in a straight line, the right one by path
    assert left.distance_to(zone_a) < right.distance_to(zone_a)
    assert field.distance(right.x, right.y) < field.distance(left.x, left.y)
    # and the field's length is the grid path's, close to the route driven
    route = field.route(right.x, right.y)
    assert route is not None
    assert field.distance(right.x, right.y) == pytest.approx(route.length, rel=0.05)
    # A point inside the wall is no place to measure from; off the map neither
    assert field.distance(5.0, 1.0) == math.inf
    assert field.distance(-3.0, 1.0) == math.inf
    # The same goal cell is searched once
    assert floor.open.field(zone_a.x, zone_a.y) is field


def test_a_closed_zones_area_is_driven_around_and_left(rooms: TwoRooms) -> None:
    # Given zone B with an area across the west room's lower half
    fleet = load_fleet(rooms.fleet_file)
    area = [Point(0.3, 0.3), Point(4.7, 0.3), Point(4.7, 2.6), Point(0.3, 2.6)]
    zones = [msgspec.structs.replace(z, area=area) if z.id == "B" else z for z in fleet.zones]
    floor = FleetFloor(msgspec.structs.replace(fleet, zones=zones), load_map(rooms.map_file))
    closed = floor.planner({"B"})
    # When B is closed, a robot inside it (the left rover) may not stand there
    left = fleet.robot("left").start
    assert floor.open.may_stand(left.x, left.y) and not closed.may_stand(left.x, left.y)
    # Then it leaves by the shortest way over free ground, to a place it may stand
    out = closed.escape(left.x, left.y)
    assert out is not None and closed.may_stand(*out.points[-1])
    assert out.points[-1][1] > 2.6 and out.length < 2.5
    # and a path from the loading zone to zone A keeps out of the area
    loading, zone_a = fleet.zone("LOADING").pose, fleet.zone("A").pose
    route = closed.plan((loading.x, loading.y), (zone_a.x, zone_a.y))
    assert route is not None and on_drivable_cells(closed, route)
    # An area-less zone closes no ground: the open planner serves it
    assert floor.planner({"A"}) is floor.open


@pytest.mark.parametrize(
    ("pose", "reason"),
    [
        ("{x: 5.0, y: 1.0}", "zones.1.pose: (5, 1) is inside a wall on the map two-rooms.yaml, so no robot can reach it"),
        ("{x: 12.0, y: 1.0}", "zones.1.pose: (12, 1) is off the map two-rooms.yaml (x 0 to 10, y 0 to 5), so no robot can reach it"),
        ("{x: 5.2, y: 1.0}", "zones.1.pose: (5.2, 1) is 0.12 m from a wall; a robot needs 0.2 m (floor.robot_radius), so no robot can reach it"),
    ],
)  # fmt: skip
def test_a_zone_where_no_robot_can_be_is_one_line(rooms: TwoRooms, pose: str, reason: str) -> None:
    text = rooms.fleet_file.read_text().replace("{x: 6.0, y: 0.8, theta: 0.0}", pose)
    rooms.fleet_file.write_text(text)
    with pytest.raises(MapError) as raised:
        load_floor(load_fleet(rooms.fleet_file))
    assert str(raised.value) == reason


def test_a_room_no_path_leads_into_is_refused(tmp_path: Path) -> None:
    # Given two rooms with no gap in the wall between them
    shades = np.full((40, 80), FREE, dtype=np.uint8)
    shades[:2, :] = shades[-2:, :] = shades[:, :2] = shades[:, -2:] = OCCUPIED
    shades[:, 38:42] = OCCUPIED
    write_map(tmp_path, shades, name="sealed")
    fleet = tmp_path / "fleet.yaml"
    fleet.write_text(
        "floor: {map: sealed.yaml}\n"
        "robots: [{thing: r1, spoken: [rover], start: {x: 0.8, y: 1.0}}]\n"
        "zones:\n"
        "  - {id: LOADING, spoken: [loading zone], pose: {x: 0.8, y: 0.5}, radius: 0.2}\n"
        "  - {id: A, spoken: [zone a], pose: {x: 3.2, y: 1.0}, radius: 0.2}\n"
    )
    with pytest.raises(
        MapError, match=r"^zones.1.pose: \(3.2, 1\) cannot be reached from robots.0.start"
    ):
        load_floor(load_fleet(fleet))


def test_a_map_is_named_relative_to_its_fleet_file(rooms: TwoRooms) -> None:
    fleet = load_fleet(rooms.fleet_file)
    assert fleet.floor is not None and fleet.floor.map == str(rooms.map_file)
    floor = load_floor(fleet)
    assert floor is not None
    drawn = floor.drawn()
    assert (drawn.width, drawn.height, drawn.origin) == (10.0, 5.0, Point(0.0, 0.0))


def test_many_robots_are_measured_in_one_call_as_one_by_one(floor: FleetFloor) -> None:
    zone_a = floor.fleet.zone("A").pose
    field = floor.open.field(zone_a.x, zone_a.y)
    points = [(4.3, 0.8), (9.0, 4.0), (5.0, 1.0), (-3.0, 1.0), (6.0, 0.8), (0.4, 4.6)]
    xs, ys = [x for x, _ in points], [y for _, y in points]
    assert field.distances(xs, ys) == [field.distance(x, y) for x, y in points]
