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
from robot_agent.config import SimSettings
from vahr.protocol import Pose

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.clock import Clock
    from vahr.protocol import Zone


@dataclass
class _Faults:
    stuck_next: bool = False
    fail_next: str | None = None
    stuck_zones: set[str] = field(default_factory=set)
    fail_zones: set[str] = field(default_factory=set)


class SimBackend:
    """A robot that moves at `speed_mps` and turns at `turn_rate_rps` in simulated time."""

    name = "sim"

    def __init__(self, *, start: Pose, clock: Clock, settings: SimSettings | None = None) -> None:
        self.settings = settings or SimSettings()
        self._clock = clock
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
        await self._turn_to(heading)
        tick = self.settings.tick_s
        travelled = 0.0
        # Where a stuck or failing goal stops: half way, or where an injection found it.
        halt_at = total / 2
        last = self._clock.monotonic()
        while travelled < total:
            await self._clock.sleep(tick)
            # A fault injected while driving applies from where the robot is now.
            if self._faults.stuck_next or self._faults.fail_next:
                stuck = stuck or self._faults.stuck_next
                failure = failure or self._faults.fail_next
                self._faults.stuck_next, self._faults.fail_next = False, None
                halt_at = travelled
            # Integrate over the time that really passed, so a busy machine (or a high
            # speed factor) changes how often the pose is updated, never the robot's speed.
            now = self._clock.monotonic()
            elapsed, last = now - last, now
            if (stuck or failure) and travelled >= halt_at:
                if failure:
                    raise NavigationFailed(f"goal to {zone.id} aborted: {failure}")
                # Stuck: the robot holds its place and keeps reporting the same progress,
                # which is what the executor's stuck detection must notice.
                on_progress(Progress(travelled / total, self._pose))
                continue
            travelled = min(total, travelled + self.settings.speed_mps * elapsed)
            if stuck or failure:
                travelled = min(travelled, halt_at)
            self._pose = Pose(
                start.x + (goal.x - start.x) * travelled / total,
                start.y + (goal.y - start.y) * travelled / total,
                heading,
            )
            on_progress(Progress(travelled / total, self._pose))
        await self._turn_to(goal.theta)
        self._pose = Pose(goal.x, goal.y, goal.theta)
        on_progress(Progress(1.0, self._pose))

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
        # The simulator stops within one tick once the driving task is cancelled.
        await asyncio.sleep(0)

    async def close(self) -> None:
        return None
