"""The rules a fleet file is held to before anything runs it: names used once, groups of
the fleet's robots, poses a robot can reach; each broken file is one line naming the entry."""

from __future__ import annotations

import pytest

from tests.support.fleets import BAD_FLEETS, SIX_ROBOTS, bad_fleet
from vahr.commands.fleet_flag import read_fleet
from vahr.domain.fleet import Fleet, Floor, Point, Pose
from vahr.errors import VahrError
from vahr.local.robots import fleet_of
from vahr.protocol import ProtocolError

ROBOT = "robots: [{thing: r, spoken: [r], start: {x: 1, y: 1}}]\n"
ZONES = "zones: [{id: LOADING, spoken: [l], pose: {x: 2, y: 2}}]\n"


def test_the_six_robot_fleet_loads_with_its_group_and_floor() -> None:
    fleet = read_fleet(SIX_ROBOTS)
    assert len(fleet.robots) == 6
    assert [group.id for group in fleet.groups] == ["all", "waders"]
    assert fleet.layout().width == 24.0


@pytest.mark.parametrize("name", sorted(BAD_FLEETS))
def test_a_broken_fleet_file_is_one_line_naming_the_file_and_the_entry(name: str) -> None:
    # Given a fleet file with one mistake, when a command reads it
    path = bad_fleet(name)
    with pytest.raises(VahrError) as raised:
        read_fleet(path)
    # Then the error is one line: the file, the entry and the reason
    assert str(raised.value) == f"{path}: {BAD_FLEETS[name]}"


def test_a_missing_fleet_file_says_it_cannot_be_read() -> None:
    with pytest.raises(VahrError, match=r"nope\.yaml: cannot read the fleet file \(No such file"):
        read_fleet(bad_fleet("nope"))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "robots: [{thing: r, spoken: [everyone], start: {x: 1, y: 1}}]\n" + ZONES,
            "robots.0.spoken.0: 'everyone' is used twice (also the fleet's default names, "
            "as no group is `all`)",
        ),
        (
            ROBOT + "zones: [{id: LOADING, spoken: [r], pose: {x: 2, y: 2}}]\n",
            "zones.0.spoken.0: 'r' is used twice (also robots.0.spoken.0)",
        ),
        (
            ROBOT + ZONES + "groups: [{id: g, spoken: [g]}, {id: h, spoken: [G], robots: []}]\n",
            "groups.0.robots: is required but missing",
        ),
        (
            ROBOT + ZONES + "groups: [{id: g, spoken: [g], robots: []}, "
            "{id: h, spoken: [' G  '], robots: []}]\n",
            "groups.1.spoken.0: 'g' is used twice (also groups.0.spoken.0)",
        ),
        (
            ROBOT + ZONES + "groups: [{id: g, spoken: ['  '], robots: []}]\n",
            "groups.0.spoken.0: is blank",
        ),
        (
            "robots: [{thing: r, spoken: [r], start: {x: .nan, y: 1}}]\n" + ZONES,
            "robots.0.start.x: is not a finite number",
        ),
        (
            ROBOT + "zones: [{id: LOADING, spoken: [l], pose: {x: 2, y: 2, theta: .inf}}]\n",
            "zones.0.pose.theta: is not a finite number",
        ),
        (
            ROBOT + ZONES + "floor: {width: 5, height: 5, led: {x: .inf, y: 1}}\n",
            "floor.led.x: is not a finite number",
        ),
        (
            ROBOT + ZONES + "floor: {width: 5, height: 5, origin: {x: 1.5, y: 0}}\n",
            "robots.0.start: (1, 1) is outside the floor (x 1.5 to 6.5, y 0 to 5), so the "
            "robot cannot start there",
        ),
        (
            # The system's own identities (vahr.protocol.identities): never a robot's name.
            "robots: [{thing: vahr-station-lab, spoken: [r], start: {x: 1, y: 1}}]\n" + ZONES,
            "robots.0.thing: 'vahr-station-lab' is reserved: names starting with 'vahr-' are "
            "the system's own identities (services, stations, recorders), never a robot's",
        ),
    ],
)
def test_fleet_rules_name_the_entry(text: str, message: str) -> None:
    with pytest.raises(ProtocolError) as raised:
        Fleet.from_yaml(text)
    assert str(raised.value) == message


def test_a_pose_on_the_floors_edge_is_on_the_floor() -> None:
    fleet = Fleet.from_yaml(ROBOT + ZONES + "floor: {width: 2, height: 2, origin: {x: 1, y: 1}}\n")
    assert fleet.floor is not None and fleet.floor.holds(Pose(3.0, 1.0))


def test_robots_added_past_the_fleet_grow_the_floor_to_hold_them(fleet: Fleet) -> None:
    # Given the paper's fleet and its 10.5 m by 8 m floor, when vahr up --robots 5 adds three
    grown = fleet_of(5, fleet)
    # Then the added robots start west of the building, on a floor grown to hold them
    assert grown.floor is not None and fleet.floor is not None
    assert [robot.start.x for robot in grown.robots[2:]] == [-1.0, -1.0, -1.0]
    assert (grown.floor.origin, grown.floor.width) == (Point(-2.0, 0.0), 12.5)
    assert grown.floor.walls == fleet.floor.walls
    # and a floor that already holds every point is kept as it is
    floor = Floor(width=4.0, height=4.0)
    assert floor.covering([Pose(1.0, 1.0)]) is floor
