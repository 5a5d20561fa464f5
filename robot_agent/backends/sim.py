"""The kinematic simulator backend: turn in place, drive straight, turn to the zone's heading.

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
from robot_agent.backends.sim_ticker import SimTicker
from robot_agent.config import SimSettings
from vahr.domain import Pose

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.clock import Clock
    from vahr.domain import Zone


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
    ) -> None:
        """`ticker` steps this robot's drives; robots sharing one event loop (a swarm)
        should share one. Without it, the robot has a ticker of its own."""
        self.settings = settings or SimSettings()
        self._clock = clock
        self._ticker = ticker or SimTicker(clock=clock, tick_s=self.settings.tick_s)
        self._pose = start
        self._faults = _Faults(
            stuck_zones=set(self.settings.stuck_zones), fail_zones=set(self.settings.fail_zones)
        )

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

    async def go_to(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        stuck = self._faults.stuck_next or zone.id in self._faults.stuck_zones
        failure = self._faults.fail_next or (
            "the planner found no path" if zone.id in self._faults.fail_zones else None
        )
        self._faults.stuck_next, self._faults.fail_next = False, None
        goal = zone.pose
        start = self._pose
        total = start.distance_to(goal)
        heading = math.atan2(goal.y - start.y, goal.x - start.x) if total > 1e-6 else start.theta
        # The first observation, before turning: it tells the executor at once that this
        # backend times its motion (`Progress.at`), so no watchdog runs on the clock.
        on_progress(Progress(0.0, start, self._clock.monotonic()))
        await self._turn_to(heading)
        if total > 1e-6:
            drive = _Drive(self, zone, on_progress, heading=heading, stuck=stuck, failure=failure)
            self._ticker.add(drive)
            try:
                await drive.ended
            finally:
                # Cancelled (preempted, stopped): the robot stays where the last step left it.
                self._ticker.discard(drive)
        await self._turn_to(goal.theta)
        self._pose = Pose(goal.x, goal.y, goal.theta)
        on_progress(Progress(1.0, self._pose, self._clock.monotonic()))

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
        await self._clock.sleep(delay)

    async def halt(self) -> None:
        # The simulator stops at once when the driving task is cancelled (its drive leaves
        # the ticker then).
        await asyncio.sleep(0)

    async def close(self) -> None:
        return None


class _Drive:
    """One straight drive of a `SimBackend` to its goal, stepped by a `SimTicker`."""

    def __init__(
        self,
        backend: SimBackend,
        zone: Zone,
        on_progress: Callable[[Progress], None],
        *,
        heading: float,
        stuck: bool,
        failure: str | None,
    ) -> None:
        self.backend = backend
        self.zone = zone
        self.on_progress = on_progress
        self.heading = heading
        self.start = backend.pose
        self.total = self.start.distance_to(zone.pose)
        self.travelled = 0.0
        self.stuck, self.failure = stuck, failure
        # Where a stuck or failing goal stops: half way, or where an injection found it.
        self.halt_at = self.total / 2
        self.last = backend._clock.monotonic()
        self.ended: asyncio.Future[None] = asyncio.get_running_loop().create_future()

    def step(self, now: float) -> bool:
        if self.ended.done():  # the awaiting go_to was cancelled
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
        total = self.total
        if (self.stuck or self.failure) and self.travelled >= self.halt_at:
            if self.failure:
                self.ended.set_exception(
                    NavigationFailed(f"goal to {self.zone.id} aborted: {self.failure}")
                )
                return True
            # Stuck: the robot holds its place and keeps reporting the same progress, with
            # the time that passed, which is what the executor's stuck detection notices.
            self.on_progress(Progress(self.travelled / total, backend.pose, now))
            return False
        travelled = min(total, self.travelled + backend.settings.speed_mps * elapsed)
        if self.stuck or self.failure:
            travelled = min(travelled, self.halt_at)
        self.travelled = travelled
        goal, start = self.zone.pose, self.start
        backend._pose = Pose(
            start.x + (goal.x - start.x) * travelled / total,
            start.y + (goal.y - start.y) * travelled / total,
            self.heading,
        )
        self.on_progress(Progress(travelled / total, backend._pose, now))
        if travelled >= total:
            self.ended.set_result(None)
            return True
        return False

    def crash(self, error: BaseException) -> None:
        if not self.ended.done():
            self.ended.set_exception(error)
