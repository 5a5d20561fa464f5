"""The kinematic simulator backend: turn in place, drive the path, turn to the zone's heading.

On a drawn floor the path is the straight line. On a map (`floor: {map: FILE}`) it is the
path `vahr.navigation` plans on the map inflated by the robot's radius, around closed
zones' areas, and the robot drives its straight legs one after another, never through an
occupied cell; its progress and its time to arrival are measured along that path, and a
zone that closes while it drives makes it plan again from where it is.

Speeds are in simulated time (see `ScaledClock`), so `--sim-speed-factor 50` makes a demo
fifty times faster without changing the physics. Faults can be injected to test what the
executor does when a robot gets stuck or a goal fails, from configuration (zones that
always fail or stick) or at run time (`inject_stuck`, `inject_failure`).
"""

from __future__ import annotations

import asyncio
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from robot_agent.backends.port import NavigationFailed, Progress
from robot_agent.backends.sim_battery import BatteryTicker, SimBattery
from robot_agent.backends.sim_ticker import SimTicker
from robot_agent.config import SimSettings
from vahr.domain import Pose
from vahr.domain.battery import NO_DRAIN

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.clock import Clock
    from vahr.domain import Zone
    from vahr.domain.battery import BatteryType
    from vahr.navigation import FleetFloor
    from vahr.protocol import Battery

# A robot leaving a closed zone's circle on a drawn floor stops this far outside it.
LEAVE_MARGIN_M = 0.3
# A planned path is reported (`Progress.path`) with at most this many points: the shadow
# carries it, and a path with more legs is thinned, keeping its ends.
PATH_POINTS_MAX = 40


@dataclass(frozen=True)
class Way:
    """The way a drive takes: points from the robot to its goal, and the length (m). A
    straight line on a drawn floor; on a map, `vahr.navigation`'s planned `Route`."""

    points: tuple[tuple[float, float], ...]
    length: float


@dataclass
class _Faults:
    stuck_next: bool = False
    fail_next: str | None = None
    stuck_zones: set[str] = field(default_factory=set)
    fail_zones: set[str] = field(default_factory=set)


class SimBackend:
    """A robot that moves at `speed_mps` and turns at `turn_rate_rps` in simulated time."""

    name = "sim"
    observed_pose = False

    def __init__(
        self,
        *,
        start: Pose,
        clock: Clock,
        settings: SimSettings | None = None,
        ticker: SimTicker | None = None,
        floor: FleetFloor | None = None,
        battery: BatteryType | None = None,
        chargers: tuple[Zone, ...] = (),
        battery_ticker: BatteryTicker | None = None,
    ) -> None:
        """`ticker` steps this robot's drives; robots sharing one event loop (a swarm)
        should share one. Without it, the robot has a ticker of its own. `floor` is the
        fleet's map (`vahr.navigation.load_floor`), shared by a swarm's robots; without
        it the robot drives straight. `battery` is how its battery drains and charges (the
        fleet's rates for its type; without it, it never drains) at the `chargers`;
        `battery_ticker` settles it while it stands (shared like `ticker`)."""
        self.settings = settings or SimSettings()
        self._clock = clock
        self._ticker = ticker or SimTicker(clock=clock, tick_s=self.settings.tick_s)
        self._pose = start
        self._faults = _Faults(
            stuck_zones=set(self.settings.stuck_zones), fail_zones=set(self.settings.fail_zones)
        )
        self.floor = floor
        self.closed: frozenset[str] = frozenset()
        self._drive: _Drive | None = None
        self.battery = SimBattery(
            clock=clock, pose=lambda: self._pose, rates=battery or NO_DRAIN, chargers=chargers
        )
        self._battery_ticker = battery_ticker or BatteryTicker(clock=clock)

    def watch_battery(self, on_battery: Callable[[Battery], None]) -> None:
        """Report the battery now and whenever its whole percent or charging changes."""
        self.battery.watch(on_battery)
        if self.battery.changes_unwatched:
            self._battery_ticker.add(self.battery)

    def set_battery(self, percent: float) -> None:
        """Set the charge (a fault injected for tests and demos)."""
        self.battery.set_percent(percent)

    @property
    def pose(self) -> Pose:
        return self._pose

    def inject_stuck(self) -> None:
        """The robot stops where it is and never arrives (a blocked corridor): at once on
        the way it is driving, else half way along its next goal."""
        self._faults.stuck_next = True

    def inject_failure(self, reason: str = "the planner found no path") -> None:
        """The goal aborts with `reason` (as move_base aborts): at once on the way it is
        driving, else half way along its next goal."""
        self._faults.fail_next = reason

    def clear_faults(self) -> None:
        """Forget injected faults not yet applied (zones configured to fail stay so)."""
        self._faults.stuck_next, self._faults.fail_next = False, None

    def close_zones(self, closed: frozenset[str]) -> None:
        """Plan around these zones' areas from now on; a drive under way plans again."""
        if closed == self.closed:
            return
        self.closed = closed
        drive = self._drive
        if drive is not None and self.floor is not None:
            drive.replan(self._route_to(drive.goal, drive.zone_id))

    def route(self, goal: Pose) -> Way | None:
        """The path from here to `goal` as this robot would drive it now."""
        return self._route_to(goal, None)

    def _route_to(self, goal: Pose, zone_id: str | None) -> Way | None:
        start = self._pose
        if self.floor is None:
            return Way(((start.x, start.y), (goal.x, goal.y)), start.distance_to(goal))
        # A robot going into a zone may drive into its area, closed or not (a command to a
        # closed zone is refused before it gets here); other closed areas are kept out.
        closed = self.closed - {zone_id} if zone_id is not None else self.closed
        found = self.floor.planner(closed).plan((start.x, start.y), (goal.x, goal.y))
        return None if found is None else Way(found.points, found.length)

    async def go_to(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        self.battery.settle()
        if self.battery.empty:
            raise NavigationFailed(f"goal to {zone.id} aborted: the battery is empty")
        stuck = self._faults.stuck_next or zone.id in self._faults.stuck_zones
        failure = self._faults.fail_next or (
            "the planner found no path" if zone.id in self._faults.fail_zones else None
        )
        self._faults.stuck_next, self._faults.fail_next = False, None
        route = self._route_to(zone.pose, zone.id)
        if route is None:
            raise NavigationFailed(f"goal to {zone.id} aborted: no path to it on the map")
        self.battery.set_working(True)
        try:
            await self._drive_route(route, zone.pose, zone.id, on_progress, stuck, failure)
        finally:
            self.battery.set_working(False)

    async def leave(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        """Drive out of `zone` (its area, or its arrival circle) to the nearest place a
        robot may stand outside it; at once nothing, when the robot is not in it."""
        here = self._pose
        if self.floor is None:
            # A drawn floor: straight out of the circle, away from its centre.
            away = here.distance_to(zone.pose)
            if away > zone.radius:
                return
            heading = math.atan2(here.y - zone.pose.y, here.x - zone.pose.x) if away else here.theta
            reach = zone.radius + LEAVE_MARGIN_M
            goal = Pose(
                zone.pose.x + reach * math.cos(heading),
                zone.pose.y + reach * math.sin(heading),
                heading,
            )
            route: Way = Way(((here.x, here.y), (goal.x, goal.y)), here.distance_to(goal))
        else:
            if not self.floor.inside(zone, here):
                return
            found = self.floor.leaving(zone.id, self.closed).escape(here.x, here.y)
            if found is None:
                raise NavigationFailed(f"no way out of zone {zone.id} on the map")
            route = Way(found.points, found.length)
            end = route.points[-1]
            goal = Pose(end[0], end[1], _heading(route.points, here.theta))
        self.battery.set_working(True)
        try:
            await self._drive_route(route, goal, None, on_progress, False, None)
        finally:
            self.battery.set_working(False)

    async def _drive_route(
        self,
        route: Way,
        goal: Pose,
        zone_id: str | None,
        on_progress: Callable[[Progress], None],
        stuck: bool,
        failure: str | None,
    ) -> None:
        start = self._pose
        points = _thinned(route.points)
        heading = _heading(points, start.theta)
        # The first observation, before turning: it tells the executor at once that this
        # backend times its motion (`Progress.at`), so no watchdog runs on the clock.
        on_progress(
            Progress(
                0.0,
                start,
                self._clock.monotonic(),
                path=points if self.floor is not None else None,
                eta_s=route.length / self.settings.speed_mps,
            )
        )
        await self._turn_to(heading)
        if route.length > 1e-6:
            drive = _Drive(self, goal, zone_id, route, on_progress, stuck=stuck, failure=failure)
            self._drive = drive
            self._ticker.add(drive)
            try:
                await drive.ended
            finally:
                # Cancelled (preempted, stopped): the robot stays where the last step left it.
                self._ticker.discard(drive)
                self._drive = None
        await self._turn_to(goal.theta)
        self._pose = Pose(goal.x, goal.y, goal.theta)
        on_progress(Progress(1.0, self._pose, self._clock.monotonic(), eta_s=0.0))

    async def _turn_to(self, heading: float) -> None:
        delta = math.atan2(
            math.sin(heading - self._pose.theta), math.cos(heading - self._pose.theta)
        )
        if abs(delta) > 1e-3:
            await self._clock.sleep(abs(delta) / self.settings.turn_rate_rps)
        self._pose = Pose(self._pose.x, self._pose.y, heading)

    async def operate_arm(self, zone: Zone) -> None:
        delay = (
            self.settings.loader_delay_s if zone.arm == "loader" else self.settings.unloader_delay_s
        )
        self.battery.set_working(True)
        try:
            await self._clock.sleep(delay)
        finally:
            self.battery.set_working(False)

    async def halt(self) -> None:
        # The simulator stops at once when the driving task is cancelled (its drive leaves
        # the ticker then).
        await asyncio.sleep(0)

    async def close(self) -> None:
        self._battery_ticker.discard(self.battery)


class _Drive:
    """One drive of a `SimBackend` along its route's straight legs, stepped by a `SimTicker`."""

    def __init__(
        self,
        backend: SimBackend,
        goal: Pose,
        zone_id: str | None,
        route: Way,
        on_progress: Callable[[Progress], None],
        *,
        stuck: bool,
        failure: str | None,
    ) -> None:
        self.backend = backend
        self.goal = goal
        self.zone_id = zone_id
        self.on_progress = on_progress
        self.stuck, self.failure = stuck, failure
        # The metres driven on earlier routes of this drive (it plans again when a zone
        # closes), so that the fraction done never goes back.
        self.done_before = 0.0
        self._follow(route)
        # Where a stuck or failing goal stops: half way, or where an injection found it.
        self.halt_at = self.total / 2
        self.last = backend._clock.monotonic()
        self.new_path: tuple[tuple[float, float], ...] | None = None
        self.ended: asyncio.Future[None] = asyncio.get_running_loop().create_future()

    def _follow(self, route: Way) -> None:
        points = route.points
        self.points = points
        # The distance along the route at which each leg starts.
        self.starts = [0.0]
        for a, b in zip(points, points[1:], strict=False):
            self.starts.append(self.starts[-1] + math.hypot(b[0] - a[0], b[1] - a[1]))
        self.total = max(self.starts[-1], 1e-9)
        self.travelled = 0.0
        self.leg = 0

    def replan(self, route: Way | None) -> None:
        """Follow `route` from here on (a zone closed or opened while driving); None: no
        way is left, and the drive fails."""
        if self.ended.done():
            return
        if route is None:
            what = f"to {self.zone_id}" if self.zone_id else "out of the zone"
            self.ended.set_exception(
                NavigationFailed(f"goal {what} aborted: a zone closed and no path is left")
            )
            return
        self.done_before += self.travelled
        halt_left = self.halt_at - self.travelled
        self._follow(route)
        self.halt_at = max(0.0, halt_left)
        self.new_path = _thinned(route.points)

    def step(self, now: float) -> bool:
        if self.ended.done():  # the awaiting go_to was cancelled, or a replan found no way
            return True
        backend, faults = self.backend, self.backend._faults
        # A fault injected while driving applies from where the robot is now.
        if faults.stuck_next or faults.fail_next:
            self.stuck = self.stuck or faults.stuck_next
            self.failure = self.failure or faults.fail_next
            faults.stuck_next, faults.fail_next = False, None
            self.halt_at = self.travelled
        # Integrate over the simulated time that really passed since the last step, so a
        # busy process changes how often the pose is updated, never the robot's speed.
        elapsed, self.last = max(0.0, now - self.last), now
        speed = backend.settings.speed_mps
        if (self.stuck or self.failure) and self.travelled >= self.halt_at:
            if self.failure:
                where = self.zone_id or "out of the zone"
                self.ended.set_exception(
                    NavigationFailed(f"goal to {where} aborted: {self.failure}")
                )
                return True
            # Stuck: the robot holds its place and keeps reporting the same progress, with
            # the time that passed, which is what the executor's stuck detection notices.
            self.on_progress(Progress(self._fraction(), backend.pose, now))
            return False
        travelled = min(self.total, self.travelled + speed * elapsed)
        if self.stuck or self.failure:
            travelled = min(travelled, self.halt_at)
        battery = backend.battery
        travelled = min(travelled, self.travelled + battery.range_m)
        battery.drove(travelled - self.travelled)
        self.travelled = travelled
        starts, points = self.starts, self.points
        while self.leg < len(points) - 2 and travelled > starts[self.leg + 1]:
            self.leg += 1
        a, b = points[self.leg], points[self.leg + 1]
        span = starts[self.leg + 1] - starts[self.leg]
        along = (travelled - starts[self.leg]) / span if span > 1e-9 else 1.0
        heading = math.atan2(b[1] - a[1], b[0] - a[0]) if span > 1e-9 else backend.pose.theta
        backend._pose = Pose(a[0] + (b[0] - a[0]) * along, a[1] + (b[1] - a[1]) * along, heading)
        path, self.new_path = self.new_path, None
        eta = (self.total - travelled) / speed
        self.on_progress(Progress(self._fraction(), backend._pose, now, path=path, eta_s=eta))
        if battery.empty:
            # The robot stops where its charge ran out, as a real one does.
            where = self.zone_id or "out of the zone"
            empty = NavigationFailed(f"goal to {where} aborted: the battery is empty")
            self.ended.set_exception(empty)
            return True
        if travelled >= self.total:
            self.ended.set_result(None)
            return True
        return False

    def _fraction(self) -> float:
        return (self.done_before + self.travelled) / (self.done_before + self.total)

    def crash(self, error: BaseException) -> None:
        if not self.ended.done():
            self.ended.set_exception(error)


def _heading(points: tuple[tuple[float, float], ...], otherwise: float) -> float:
    """The heading of the first leg that goes somewhere."""
    for a, b in zip(points, points[1:], strict=False):
        if math.hypot(b[0] - a[0], b[1] - a[1]) > 1e-6:
            return math.atan2(b[1] - a[1], b[0] - a[0])
    return otherwise


def _thinned(points: tuple[tuple[float, float], ...]) -> tuple[tuple[float, float], ...]:
    """The points rounded to the centimetre, at most `PATH_POINTS_MAX` of them (evenly
    chosen, the ends kept): what a report carries. The drive itself follows every point."""
    rounded = tuple((round(x, 2), round(y, 2)) for x, y in points)
    if len(rounded) <= PATH_POINTS_MAX:
        return rounded
    step = (len(rounded) - 1) / (PATH_POINTS_MAX - 1)
    return tuple(rounded[round(index * step)] for index in range(PATH_POINTS_MAX))
