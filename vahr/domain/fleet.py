"""The fleet model: robots, zones, groups and the floor, loaded from `fleet.yaml` (a contract).

The floor (`Floor`) is either drawn (size, walls, the conveyor, where the arms and the task
III LED stand: what the operator station draws, and robots drive straight across it) or a
map (`floor: {map: FILE}`, a ROS map_server YAML relative to the fleet file: robots plan
their paths on it, `vahr.navigation`). It is optional, and a fleet file without it gets a
drawn one derived from its zones and robots (`Fleet.layout`). This module reads no image:
the map itself is read, and the fleet checked against it, by `vahr.navigation`.
"""

from __future__ import annotations

import logging
import math
import os
import re
from functools import cached_property
from typing import Annotated, Literal

import msgspec

from vahr.domain.battery import DEFAULT_TYPE, NO_DRAIN, BatteryPlan, BatteryType
from vahr.domain.text import normalize
from vahr.protocol.errors import ProtocolError, from_validation_error
from vahr.protocol.identities import check_robot_thing
from vahr.protocol.topics import check_thing

# The bundled fleet definition, next to this module: in a checkout a link to the repository's
# fleet.yaml, in the wheel and the Lambda bundle a copy of it. os.path rather than pathlib
# because this module is on the Lambda's cold-start path.
DEFAULT_FLEET_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fleet.yaml")  # noqa: PTH100, PTH118, PTH120

# The group, and the ROBOT slot value, that mean every robot (commands to it go out once, on
# the fleet topic `topics.FLEET_CMD`).
FLEET_GROUP = "all"
# What people call every robot when fleet.yaml names no such group.
FLEET_GROUP_NAMES = ("all robots", "every robot", "everyone")
# The locale of `spoken`; other locales' names are `spoken_by_locale` (`spoken_in`).
SPOKEN_LOCALE = "en-US"
_WARNED_LOCALES: set[str] = set()
_log = logging.getLogger(__name__)

SpokenNames = Annotated[
    list[Annotated[str, msgspec.Meta(min_length=1)]], msgspec.Meta(min_length=1)
]


class Pose(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A planar pose in the `map` frame: metres and radians."""

    x: float
    y: float
    theta: float = 0.0

    def distance_to(self, other: Pose) -> float:
        return math.hypot(self.x - other.x, self.y - other.y)


class Point(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A point on the floor in the `map` frame, in metres."""

    x: float
    y: float


class Segment(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A straight piece of wall from `start` to `end`."""

    start: Point
    end: Point


class Conveyor(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The belt that brings packages to the loading arm: its centre line and width."""

    start: Point
    end: Point
    width: Annotated[float, msgspec.Meta(gt=0)] = 0.5


# How far a robot's body reaches from its centre, unless the floor says: a robot keeps this
# far from every wall on a map (TurtleBot3 Waffle's footprint is 0.22 m, Burger's 0.105 m).
ROBOT_RADIUS_M = 0.2


class Floor(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The floor: the rectangle from `origin` of `width` by `height` metres, its walls, the
    conveyor, where each zone's arm stands (by zone id) and the task III LED.

    With `map` (a ROS map_server YAML, relative to the fleet file; `load_fleet` makes it
    absolute) the map is the floor: `width`, `height` and `origin` are the map's, filled in
    by `vahr.navigation` when it reads it, and `robot_radius` is how far robots keep from
    anything that is not free space. Without a map, `width` and `height` are required."""

    width: Annotated[float, msgspec.Meta(gt=0)] | None = None
    height: Annotated[float, msgspec.Meta(gt=0)] | None = None
    origin: Point = Point(0.0, 0.0)
    walls: list[Segment] = []
    conveyor: Conveyor | None = None
    arms: dict[str, Point] = {}
    led: Point | None = None
    map: Annotated[str, msgspec.Meta(min_length=1)] | None = None
    robot_radius: Annotated[float, msgspec.Meta(gt=0, le=5)] = ROBOT_RADIUS_M

    @property
    def size(self) -> tuple[float, float]:
        """(width, height) in metres; a map's before `vahr.navigation` read it is unknown."""
        if self.width is None or self.height is None:
            raise ValueError(f"the size of the map {self.map} is known once the map is read")
        return self.width, self.height

    def holds(self, point: Pose | Point) -> bool:
        """Whether `point` lies on the floor's rectangle (its edges included)."""
        width, height = self.size
        return (
            self.origin.x <= point.x <= self.origin.x + width
            and self.origin.y <= point.y <= self.origin.y + height
        )

    def extent(self) -> str:
        """The rectangle in words, for errors: `x 0 to 10.5, y 0 to 8`."""
        (x, y), (width, height) = (self.origin.x, self.origin.y), self.size
        return f"x {x:g} to {x + width:g}, y {y:g} to {y + height:g}"

    def covering(self, points: list[Pose]) -> Floor:
        """This floor, its rectangle grown to hold `points` with `FLOOR_MARGIN_M` to spare
        (robots added to a fleet in code park beside the building); itself when it does."""
        outside = [point for point in points if not self.holds(point)]
        if not outside:
            return self
        width, height = self.size
        left = min([self.origin.x] + [p.x - FLOOR_MARGIN_M for p in outside])
        bottom = min([self.origin.y] + [p.y - FLOOR_MARGIN_M for p in outside])
        right = max([self.origin.x + width] + [p.x + FLOOR_MARGIN_M for p in outside])
        top = max([self.origin.y + height] + [p.y + FLOOR_MARGIN_M for p in outside])
        return msgspec.structs.replace(
            self, origin=Point(left, bottom), width=right - left, height=top - bottom
        )


# A derived floor leaves this much room around the zones and the robots' start poses.
FLOOR_MARGIN_M = 1.0
# A derived arm stands this far ahead of its zone, along the zone's heading.
ARM_OFFSET_M = 0.9


class Robot(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One robot: its thing name, the names people call it, and where it starts."""

    thing: str
    spoken: SpokenNames
    start: Pose
    # Names in other languages than en-US's `spoken`, by locale ("de-DE": [...]); left out
    # of the fleet's JSON when the file gives none.
    spoken_by_locale: dict[str, SpokenNames] | msgspec.UnsetType = msgspec.UNSET
    # The robot's type, for its battery's rates (`battery.types` in the fleet file); left
    # out of the fleet's JSON when the file gives none (`robot_type`).
    type: Annotated[str, msgspec.Meta(min_length=1, max_length=64)] | msgspec.UnsetType = (
        msgspec.UNSET
    )

    @property
    def robot_type(self) -> str:
        return self.type if isinstance(self.type, str) else DEFAULT_TYPE


class Zone(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A place robots drive to. `arm` says whether an arm loads or unloads there; a robot
    within `radius` of `pose` has arrived. `area` (a polygon in the map frame, optional) is
    the room or bay the zone stands for: while the zone is closed, robots on a map drive
    around it and leave it (`vahr.navigation`). `charger` marks a charging place."""

    id: Annotated[str, msgspec.Meta(pattern=r"^[A-Z][A-Z0-9_]{0,31}$")]
    spoken: SpokenNames
    pose: Pose
    arm: Literal["loader", "unloader"] | None = None
    radius: Annotated[float, msgspec.Meta(gt=0)] = 0.5
    spoken_by_locale: dict[str, SpokenNames] | msgspec.UnsetType = msgspec.UNSET
    area: Annotated[list[Point], msgspec.Meta(min_length=3)] | None = None
    charger: bool = False


class Group(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A named set of robots addressed at once (the fleet topic when it is every robot)."""

    id: str
    spoken: SpokenNames
    robots: list[str]
    spoken_by_locale: dict[str, SpokenNames] | msgspec.UnsetType = msgspec.UNSET


class Confirmation(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """When fleet-wide and disruptive commands are confirmed with a spoken yes first
    (`vahr.domain.people`): `enabled` None means on whenever people are known (a users
    file, or the users table on AWS); a command to more than `group_threshold` robots is
    fleet-wide."""

    enabled: bool | None = None
    group_threshold: Annotated[int, msgspec.Meta(ge=1)] = 3


class Fleet(msgspec.Struct, frozen=True, forbid_unknown_fields=True, dict=True):
    """The whole fleet definition. Build it with `load_fleet` or `Fleet.from_yaml`."""

    robots: Annotated[list[Robot], msgspec.Meta(min_length=1)]
    zones: Annotated[list[Zone], msgspec.Meta(min_length=1)]
    groups: list[Group] = []
    experiment_thing: str = "vahr-experiment"
    floor: Floor | None = None
    # Left out of the fleet's JSON when the file gives none (`confirmation_rules`).
    confirmation: Confirmation | msgspec.UnsetType = msgspec.UNSET
    # Left out of the fleet's JSON when the file gives none: batteries then never drain.
    battery: BatteryPlan | msgspec.UnsetType = msgspec.UNSET

    @property
    def battery_plan(self) -> BatteryPlan:
        """The file's battery rules, or the defaults (`vahr.domain.battery`)."""
        return self.battery if isinstance(self.battery, BatteryPlan) else _DEFAULT_PLAN

    @property
    def batteries_drain(self) -> bool:
        """Whether any robot's battery drains (the file has a `battery:` section that says
        so): only then are robots sent to charge."""
        return any(self.battery_rates(thing).drains for thing in self.robot_things)

    @cached_property
    def _types(self) -> dict[str, str]:
        return {robot.thing: robot.robot_type for robot in self.robots}

    def battery_rates(self, thing: str) -> BatteryType:
        """How `thing`'s battery drains and charges; never draining without a `battery:`
        section."""
        if not isinstance(self.battery, BatteryPlan):
            return NO_DRAIN
        return self.battery.rates(self._types.get(thing, DEFAULT_TYPE))

    @cached_property
    def chargers(self) -> tuple[Zone, ...]:
        """The zones with `charger: true`, in file order."""
        return tuple(zone for zone in self.zones if zone.charger)

    @property
    def confirmation_rules(self) -> Confirmation:
        """The file's confirmation settings, or the defaults."""
        return self.confirmation if isinstance(self.confirmation, Confirmation) else Confirmation()

    def validate(self) -> Fleet:
        """Check the rules that span fields; return self. `from_yaml` calls this.

        Each error names the entry (`robots.2.thing`, `zones.1.spoken.0`) and the reason:
        thing names valid (a robot's not one of the system's own, `vahr.protocol.identities`);
        things, zone ids, group ids, a group's members and every spoken
        name used once; a zone LOADING; a group's members robots of the fleet; every pose
        reachable (`_check_reachable`); the floor's arms at zones with an arm.
        """
        for index, robot in enumerate(self.robots):
            try:
                check_robot_thing(robot.thing)
            except ValueError as err:
                raise ProtocolError(f"robots.{index}.thing", str(err).split(": ", 1)[1]) from err
        try:
            check_thing(self.experiment_thing)
        except ValueError as err:
            raise ProtocolError("experiment_thing", str(err).split(": ", 1)[1]) from err
        _require_unique([(f"robots.{i}.thing", r.thing) for i, r in enumerate(self.robots)])
        _require_unique([(f"zones.{i}.id", zone.id) for i, zone in enumerate(self.zones)])
        _require_unique([(f"groups.{i}.id", group.id) for i, group in enumerate(self.groups)])
        if "LOADING" not in self.zone_ids:
            raise ProtocolError("zones", "a zone with id LOADING is required for deliveries")
        for index, group in enumerate(self.groups):
            self._check_members(f"groups.{index}.robots", group.robots)
        self._check_spoken_names()
        self._check_battery()
        _check_reachable(self)
        if self.floor is not None:
            with_arms = {zone.id for zone in self.zones if zone.arm is not None}
            for zone_id in self.floor.arms:
                if zone_id not in with_arms:
                    raise ProtocolError(
                        "floor.arms", f"{zone_id!r} is not a zone with an arm (arm: in zones)"
                    )
        return self

    def _check_battery(self) -> None:
        """The battery rules hold together, every robot's type is one the section lists
        (when it lists any), and batteries that drain have somewhere to charge."""
        if not isinstance(self.battery, BatteryPlan):
            return
        plan = self.battery
        if plan.reserve >= plan.charge_below:
            raise ProtocolError(
                "battery.reserve",
                f"{plan.reserve:g} must be below battery.charge_below ({plan.charge_below:g}): "
                "a robot goes to charge before it reaches its reserve",
            )
        if plan.charged <= plan.charge_below:
            raise ProtocolError(
                "battery.charged",
                f"{plan.charged:g} must be above battery.charge_below ({plan.charge_below:g})",
            )
        if plan.types:
            for index, robot in enumerate(self.robots):
                if robot.robot_type not in plan.types:
                    raise ProtocolError(
                        f"robots.{index}.type",
                        f"{robot.robot_type!r} is not a type of battery.types "
                        f"({', '.join(sorted(plan.types))})",
                    )
        if not self.chargers and self.batteries_drain:
            raise ProtocolError(
                "zones",
                "no zone has charger: true, but batteries drain (battery:); add a charging "
                "zone, or set the drain rates of battery.types to 0",
            )

    def _check_members(self, field: str, members: list[str]) -> None:
        _require_unique([(f"{field}.{i}", member) for i, member in enumerate(members)])
        for index, member in enumerate(members):
            if member in self.robot_things:
                continue
            what = "is a zone, not a robot" if member in self.zone_ids else "is not a robot"
            raise ProtocolError(
                f"{field}.{index}",
                f"{member!r} {what} of the fleet; robots are {_listed(self.robot_things)}",
            )

    def _check_spoken_names(self) -> None:
        """One name means one thing, across robots, zones and groups, as people say it
        (lower-cased, single-spaced); without a group `all`, its default names are taken."""
        spoken = [
            *((f"robots.{index}", robot.spoken) for index, robot in enumerate(self.robots)),
            *((f"zones.{index}", zone.spoken) for index, zone in enumerate(self.zones)),
            *((f"groups.{index}", group.spoken) for index, group in enumerate(self.groups)),
        ]
        named = [
            (f"{entry}.spoken.{k}", name) for entry, names in spoken for k, name in enumerate(names)
        ]
        if not any(group.id == FLEET_GROUP for group in self.groups):
            default = "the fleet's default names, as no group is `all`"
            named = [(default, name) for name in FLEET_GROUP_NAMES] + named
        said = []
        for field, name in named:
            words = " ".join(name.lower().split())
            if not words:
                raise ProtocolError(field, "is blank")
            said.append((field, words))
        _require_unique(said)

    @classmethod
    def from_yaml(cls, text: str | bytes) -> Fleet:
        if not text.strip():
            raise ProtocolError("fleet", "is empty; a fleet needs robots: and zones:")
        try:
            fleet = msgspec.yaml.decode(text, type=cls)
        except msgspec.ValidationError as err:
            error = from_validation_error(err)
            # A document that is not a mapping fails at its root, which is the fleet itself.
            field = "fleet" if error.field == "payload" else error.field
            raise ProtocolError(field, error.reason) from err
        except msgspec.DecodeError as err:
            # PyYAML's message spans lines and names its own input; one line, where it is.
            reason = re.sub(r' in "<[a-z ]+>",', " at", " ".join(str(err).split()))
            raise ProtocolError("fleet", f"is not valid YAML ({reason})") from err
        return fleet.validate()

    @cached_property
    def robot_things(self) -> tuple[str, ...]:
        return tuple(robot.thing for robot in self.robots)

    @cached_property
    def zone_ids(self) -> tuple[str, ...]:
        return tuple(zone.id for zone in self.zones)

    def robot(self, thing: str) -> Robot:
        for robot in self.robots:
            if robot.thing == thing:
                return robot
        raise KeyError(thing)

    def zone(self, zone_id: str) -> Zone:
        for zone in self.zones:
            if zone.id == zone_id:
                return zone
        raise KeyError(zone_id)

    def zone_at(self, pose: Pose) -> Zone | None:
        """The zone whose circle contains `pose`, if any."""
        for zone in self.zones:
            if zone.pose.distance_to(pose) <= zone.radius:
                return zone
        return None

    def layout(self) -> Floor:
        """The floor to draw: `floor` from the file, completed with a derived arm for each
        zone with an arm it does not place; without `floor`, one derived from the zones and
        the robots' start poses (a rectangle around them with `FLOOR_MARGIN_M` to spare).
        A map's floor is drawn once `vahr.navigation` has filled in the map's size."""
        floor = self.floor or _derived_floor(self)
        arms = dict(floor.arms)
        for zone in self.zones:
            if zone.arm is not None and zone.id not in arms:
                arms[zone.id] = Point(
                    round(zone.pose.x + ARM_OFFSET_M * math.cos(zone.pose.theta), 3),
                    round(zone.pose.y + ARM_OFFSET_M * math.sin(zone.pose.theta), 3),
                )
        return msgspec.structs.replace(floor, arms=arms)

    def spoken_name(self, thing: str, locale: str = SPOKEN_LOCALE) -> str:
        """The name a person would use for a robot: the first of its spoken names."""
        return spoken_in(self.robot(thing), locale)[0]


def names_by_locale(entry: Robot | Zone | Group) -> dict[str, list[str]]:
    """A robot's, zone's or group's names in other locales than en-US, by locale."""
    names = entry.spoken_by_locale
    return names if isinstance(names, dict) else {}


def spoken_in(entry: Robot | Zone | Group, locale: str = SPOKEN_LOCALE) -> list[str]:
    """What people call a robot, zone or group in `locale`: `spoken` in en-US, else its
    `spoken_by_locale` names; a fleet file without them falls back to the en-US names
    and says so once per locale."""
    if locale == SPOKEN_LOCALE:
        return entry.spoken
    names = names_by_locale(entry).get(locale)
    if names:
        return names
    if locale not in _WARNED_LOCALES:
        _WARNED_LOCALES.add(locale)
        _log.warning(
            "fleet: %r and maybe others have no %s names (spoken_by_locale); their en-US "
            "names are used",
            getattr(entry, "thing", None) or getattr(entry, "id", ""),
            locale,
        )
    return entry.spoken


def zone_phrase(zone: Zone) -> str:
    """The zone's name as it reads inside a sentence, in en-US: its first spoken name as
    the fleet file writes it ("ward three", "the pharmacy", "zone A"), with "the" before it
    when the file also lists it so ("loading zone" is "the loading zone" when the file
    writes both). Single letters are capitals, as they are spoken as letters; a name that
    is a letter alone is "zone X", since a letter cannot stand in a sentence."""
    names = [normalize(name) for name in zone.spoken]
    first = names[0]
    if len(first) == 1:
        return f"zone {first.upper()}"
    if not first.startswith("the ") and f"the {first}" in names:
        first = f"the {first}"
    return _upper_letters(first)


def zone_name_in(zone: Zone, locale: str = SPOKEN_LOCALE) -> str:
    """The zone's name inside a sentence in `locale`: `zone_phrase` in en-US; in another
    language its first name there, each word capitalised as written nouns are ("zone a" is
    "Zone A", "ladezone" "Ladezone"): its sentences are built to need no article."""
    if locale == SPOKEN_LOCALE:
        return zone_phrase(zone)
    names = spoken_in(zone, locale)
    return " ".join(
        word.upper() if len(word) == 1 else word.capitalize() for word in names[0].split()
    )


def reason_said(reason: str, zone_id: str | None, zone_name: str) -> str:
    """A robot's reason with the zone it names by id (`zone_id`, the zone its command was
    for: `LastCommand.zone`, an event's `zone`) said by `zone_name`: "goal to PHARMACY
    aborted" is "goal to the pharmacy aborted". Only that id, as a whole word, is replaced,
    and not where the name is said already ("no path to zone A" stays as it is)."""
    if not zone_id:
        return reason
    ends_with_id = zone_name.lower().endswith(zone_id.lower())
    lead = zone_name[: len(zone_name) - len(zone_id)].lower() if ends_with_id else None

    def said(match: re.Match[str]) -> str:
        if lead and reason[: match.start()].lower().endswith(lead):
            return match.group(0)
        return zone_name

    word = rf"(?<![A-Za-z0-9_]){re.escape(zone_id)}(?![A-Za-z0-9_])"
    return re.sub(word, said, reason)


def _upper_letters(name: str) -> str:
    return " ".join(word.upper() if len(word) == 1 else word for word in name.split())


def _derived_floor(fleet: Fleet) -> Floor:
    xs = [z.pose.x - z.radius for z in fleet.zones] + [z.pose.x + z.radius for z in fleet.zones]
    ys = [z.pose.y - z.radius for z in fleet.zones] + [z.pose.y + z.radius for z in fleet.zones]
    xs += [robot.start.x for robot in fleet.robots]
    ys += [robot.start.y for robot in fleet.robots]
    left, bottom = min(xs) - FLOOR_MARGIN_M, min(ys) - FLOOR_MARGIN_M
    right, top = max(xs) + FLOOR_MARGIN_M, max(ys) + FLOOR_MARGIN_M
    corners = [Point(left, bottom), Point(right, bottom), Point(right, top), Point(left, top)]
    return Floor(
        width=right - left,
        height=top - bottom,
        origin=corners[0],
        walls=[Segment(corners[i], corners[(i + 1) % 4]) for i in range(4)],
    )


def _require_unique(entries: list[tuple[str, str]]) -> None:
    """Each (field, value) pair's value once; the second use is the error, naming the first."""
    first: dict[str, str] = {}
    for field, value in entries:
        if value in first:
            raise ProtocolError(field, f"{value!r} is used twice (also {first[value]})")
        first[value] = field


_DEFAULT_PLAN = BatteryPlan()

# An error lists at most this many robots of the fleet.
LISTED_MAX = 8


def _listed(values: tuple[str, ...]) -> str:
    shown = ", ".join(values[:LISTED_MAX])
    return shown if len(values) <= LISTED_MAX else f"{shown} and {len(values) - LISTED_MAX} more"


def _check_reachable(fleet: Fleet) -> None:
    """Every pose is one a simulated robot can stand at or drive to.

    On a drawn floor the simulator drives in a straight line from anywhere to anywhere
    (walls are drawn, not driven around), so a pose is unreachable only when it is not a
    place at all: a coordinate or heading that is not a finite number, or, when the file
    gives a `floor`, a point outside its rectangle. Without a floor, the one drawn is
    derived around every pose, which therefore lies on it. On a map, whether a pose is in
    free space and connected to the others is for `vahr.navigation` to say, which reads it.
    """
    floor = fleet.floor
    if floor is not None:
        if floor.map is None:
            for field, size in (("floor.width", floor.width), ("floor.height", floor.height)):
                if size is None:
                    raise ProtocolError(field, "is required unless floor.map names a map")
        for field, value in (("floor.width", floor.width), ("floor.height", floor.height)):
            if value is not None and not math.isfinite(value):
                raise ProtocolError(field, "is not a finite number")
        for field, point in _floor_points(floor):
            _check_finite(field, point)
    places = [
        (f"robots.{index}.start", robot.start, "the robot cannot start there")
        for index, robot in enumerate(fleet.robots)
    ]
    places += [
        (f"zones.{index}.pose", zone.pose, "no robot can reach it")
        for index, zone in enumerate(fleet.zones)
    ]
    for index, zone in enumerate(fleet.zones):
        for corner, point in enumerate(zone.area or []):
            _check_finite(f"zones.{index}.area.{corner}", point)
    drawn = floor is not None and floor.map is None
    for field, pose, consequence in places:
        _check_finite(field, pose)
        if drawn and floor is not None and not floor.holds(pose):
            raise ProtocolError(
                field,
                f"({pose.x:g}, {pose.y:g}) is outside the floor ({floor.extent()}), "
                f"so {consequence}",
            )


def _check_finite(field: str, point: Pose | Point) -> None:
    for name in point.__struct_fields__:
        if not math.isfinite(getattr(point, name)):
            raise ProtocolError(f"{field}.{name}", "is not a finite number")


def _floor_points(floor: Floor) -> list[tuple[str, Point]]:
    points = [("floor.origin", floor.origin)]
    for index, wall in enumerate(floor.walls):
        points += [
            (f"floor.walls.{index}.start", wall.start),
            (f"floor.walls.{index}.end", wall.end),
        ]
    if floor.conveyor is not None:
        points += [("floor.conveyor.start", floor.conveyor.start)]
        points += [("floor.conveyor.end", floor.conveyor.end)]
    points += [(f"floor.arms.{zone_id}", point) for zone_id, point in floor.arms.items()]
    if floor.led is not None:
        points.append(("floor.led", floor.led))
    return points


def load_fleet(path: str | os.PathLike[str] | None = None) -> Fleet:
    """Read and validate a fleet file (default: the bundled `fleet.yaml`). A map the floor
    names (`floor.map`) is taken relative to the fleet file and made absolute here."""
    file = os.fspath(path) if path is not None else DEFAULT_FLEET_FILE
    try:
        # pathlib is avoided on purpose: this module is on the Lambda's cold-start path.
        with open(file, "rb") as stream:  # noqa: PTH123
            text = stream.read()
    except OSError as err:
        raise ProtocolError("fleet", f"cannot read {file}: {err.strerror}") from err
    return map_beside(Fleet.from_yaml(text), file)


def map_beside(fleet: Fleet, fleet_file: str | os.PathLike[str]) -> Fleet:
    """The fleet with its floor's map (a path relative to the fleet file, as the contract
    says) made absolute, so it reads the same from any directory and any copy of the fleet."""
    floor = fleet.floor
    if floor is None or floor.map is None or os.path.isabs(floor.map):  # noqa: PTH117
        return fleet
    here = os.path.dirname(os.path.abspath(os.fspath(fleet_file)))  # noqa: PTH100, PTH120
    absolute = os.path.normpath(os.path.join(here, floor.map))  # noqa: PTH118
    return msgspec.structs.replace(fleet, floor=msgspec.structs.replace(floor, map=absolute))
