"""The cost of a robot for a task, and the ranking of robots by it.

The cost (docs/dispatch.md) is the length of the path from the robot's reported pose to
the task's pickup zone and from there to its drop zone. On a drawn floor robots drive
straight from anywhere to anywhere (walls are drawn, not driven around), so the path is
the straight line (`STRAIGHT`). On a map, a host passes `Routes` whose `field(zone)` is the
planned path length from every point to the zone, from one search from the zone
(`vahr.navigation` on the local host, `vahr.dispatch.grid_routes` in the Lambda): ranking
1,000 robots then costs one lookup each. A robot no path leads from is never ranked.
Robots that are idle rank before robots busy with work the dispatcher did not give them (a
command by name), whatever the distance; equal costs are broken by thing name, so the
same state always picks the same robot.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, Protocol

import msgspec

from vahr.domain.fleet import Pose

# At run time: msgspec reads RobotState's annotations when it decodes one.
from vahr.protocol.shadow import Battery  # noqa: TC001

if TYPE_CHECKING:
    from vahr.dispatch.tasks import Task
    from vahr.domain.fleet import Fleet, Zone

# Statuses of a robot with nothing to do: ranked before every busy one.
IDLE_STATUSES = frozenset({"idle", "stopped"})
# Statuses of a robot at work on something the dispatcher did not give it: it may be given
# a task (which preempts that work, as any new motion command does) but only after every
# idle robot. Any other status (stuck, error) or a disconnected robot is never a candidate.
BUSY_STATUSES = frozenset({"navigating", "loading", "unloading", "waiting"})


class RobotState(msgspec.Struct, frozen=True, kw_only=True):
    """What the dispatcher needs to know of one robot, from a fleet index (or its shadow)."""

    thing: str
    status: str
    connected: bool = True
    zone: str | None = None
    pose: Pose | None = None
    last_command_id: str | None = None
    last_result: str | None = None
    # The battery as the robot reports it (None: it reports none, and is not planned by it).
    battery: Battery | None = None
    # False while a person has taken the robot out of service: it takes no task.
    in_service: bool = True

    @property
    def available(self) -> bool:
        """Connected, in service, and idle or busy; a stuck, failed or offline robot, or one
        out of service, takes no task."""
        return (
            self.connected
            and self.in_service
            and (self.status in IDLE_STATUSES or self.status in BUSY_STATUSES)
        )

    @property
    def idle(self) -> bool:
        return self.status in IDLE_STATUSES


# The length of the path between two poses on the floor, in metres.
PathLength = Callable[[Pose, Pose], float]


def straight_line(start: Pose, end: Pose) -> float:
    """The path length on a drawn floor: robots drive straight, walls are not obstacles."""
    return math.hypot(end.x - start.x, end.y - start.y)


class DistanceField(Protocol):
    """Path lengths to one goal from anywhere on the floor, from one search. A field may
    also answer many points at once (`distances(xs, ys)`, a list of the same lengths), which
    `rank` then uses: 1,000 robots are one call."""

    def distance(self, x: float, y: float) -> float:
        """Metres along the path from (x, y) to the goal; math.inf when none leads there."""
        ...


class Routes(Protocol):
    """Path lengths on a fleet's floor, with some zones closed."""

    def field(self, zone: Zone) -> DistanceField:
        """Every point's path length to `zone`'s pose."""
        ...


class StraightLine:
    """The distance field of a drawn floor: the straight line to the goal."""

    def __init__(self, goal: Pose) -> None:
        self.x, self.y = goal.x, goal.y

    def distance(self, x: float, y: float) -> float:
        return math.hypot(x - self.x, y - self.y)


class StraightRoutes:
    """`Routes` on a drawn floor: straight lines (`straight_line`)."""

    def field(self, zone: Zone) -> DistanceField:
        return StraightLine(zone.pose)


STRAIGHT = StraightRoutes()


class EnergyCheck(Protocol):
    """Whether a robot's battery can do a task (`vahr.dispatch.energy.EnergyRule`)."""

    def after(self, task: Task) -> object:
        """What the task costs beyond the robot's way to it (the same for every robot)."""
        ...

    def can_do(self, robot: RobotState, metres: float, after: Any) -> bool:
        """Whether `robot`, `metres` from the task's end by its way there, may take it."""
        ...


def task_cost(fleet: Fleet, pose: Pose, task: Task, routes: Routes = STRAIGHT) -> float:
    """Metres a robot at `pose` drives to do `task`: to the pickup (if any), then to the
    drop zone (math.inf when no path leads there). A robot already in the drop zone of a
    navigation costs nothing."""
    drop = fleet.zone(task.zone)
    to_drop = routes.field(drop)
    if task.pickup is None:
        return to_drop.distance(pose.x, pose.y)
    pickup = fleet.zone(task.pickup)
    return routes.field(pickup).distance(pose.x, pose.y) + to_drop.distance(
        pickup.pose.x, pickup.pose.y
    )


def robot_pose(fleet: Fleet, state: RobotState) -> Pose:
    """Where a robot is: its reported pose, else its reported zone's, else its start."""
    if state.pose is not None:
        return state.pose
    if state.zone is not None and state.zone in fleet.zone_ids:
        return fleet.zone(state.zone).pose
    try:
        return fleet.robot(state.thing).start
    except KeyError:
        return Pose(0.0, 0.0)


def rank(
    fleet: Fleet,
    task: Task,
    robots: Iterable[RobotState],
    *,
    limit: int | None = None,
    routes: Routes = STRAIGHT,
    energy: EnergyCheck | None = None,
) -> list[RobotState]:
    """The robots allowed to take `task`, best first: idle before busy, then by cost, then
    by thing name. With `limit`, only the best `limit` (a partial sort: 10,000 robots are
    ranked without sorting them all). A robot no path leads from is left out, and so, with
    `energy`, is one whose battery cannot do the task and still reach a charger with its
    reserve left (`vahr.dispatch.energy`).

    The cost is `task_cost`, computed here with the pickup and drop looked up once: the
    leg from the pickup to the drop is the same for every robot, and the first leg is one
    lookup in the first zone's distance field.
    """
    drop = fleet.zone(task.zone)
    pickup = fleet.zone(task.pickup) if task.pickup is not None else None
    first = pickup or drop
    rest = routes.field(drop).distance(pickup.pose.x, pickup.pose.y) if pickup is not None else 0.0
    allowed = frozenset(task.robots)
    candidates = [robot for robot in robots if not allowed or robot.thing in allowed]
    poses = [
        robot.pose if robot.pose is not None else robot_pose(fleet, robot) for robot in candidates
    ]
    if isinstance(routes, StraightRoutes):
        hypot, fx, fy = math.hypot, first.pose.x, first.pose.y
        costs = [hypot(pose.x - fx, pose.y - fy) for pose in poses]
    else:
        field = routes.field(first)
        many = getattr(field, "distances", None)
        if many is not None:
            costs = many([pose.x for pose in poses], [pose.y for pose in poses])
        else:
            costs = [field.distance(pose.x, pose.y) for pose in poses]
    inf = math.inf
    # False sorts before True: idle robots first. A robot no path leads from is left out.
    keyed: list[tuple[bool, float, str, RobotState]] = [
        (robot.status not in IDLE_STATUSES, cost + rest, robot.thing, robot)
        for robot, cost in zip(candidates, costs, strict=True)
        if cost != inf
    ]
    if energy is not None:
        after = energy.after(task)
        keyed = [entry for entry in keyed if energy.can_do(entry[3], entry[1], after)]
    # Tuples compare field by field and thing names are unique, so the states themselves
    # are never compared.
    if limit is None:
        keyed.sort()
    elif limit == 1:
        keyed = [min(keyed)] if keyed else []
    else:
        keyed = heapq.nsmallest(limit, keyed)
    return [entry[3] for entry in keyed]
