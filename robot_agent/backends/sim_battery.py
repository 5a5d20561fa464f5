"""A simulated robot's battery: drains by the metre driven and by the hour (idle or
working), charges at a charging zone, and is read like a real robot's (`BatteryGauge`).

The rates are the fleet file's, for the robot's type (`vahr.domain.battery`). Time is the
simulator's clock, so a speed factor drains and charges faster alike. The charge changes
continuously but is reported in whole percent, and only when that or `charging` changes:
a shadow update (billed on AWS) every percent, never every tick.

One `BatteryTicker` settles every battery of a process (a swarm's thousand) every
`SETTLE_S` simulated seconds, on one timer: a battery drains while its robot stands idle,
when nothing else wakes it. A battery whose charge cannot change so is not settled: with
a fleet file without batteries, settling 10,000 robots' took a third of a swarm's CPU.
"""

from __future__ import annotations

import asyncio
import logging
import math
from typing import TYPE_CHECKING

from vahr.domain.battery import NO_DRAIN
from vahr.protocol import Battery

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.clock import Clock
    from vahr.domain import Pose, Zone
    from vahr.domain.battery import BatteryType

log = logging.getLogger(__name__)

# Simulated seconds between two settlements of every idle battery.
SETTLE_S = 5.0
FULL = 100.0


class SimBattery:
    """One robot's battery. `pose` says where the robot is (for the chargers)."""

    def __init__(
        self,
        *,
        clock: Clock,
        pose: Callable[[], Pose],
        rates: BatteryType = NO_DRAIN,
        chargers: tuple[Zone, ...] = (),
        percent: float = FULL,
    ) -> None:
        self.rates = rates
        self.chargers = chargers
        self.level = percent
        self.working = False
        self.charging = False
        self._clock = clock
        self._pose = pose
        self._last = clock.monotonic()
        self._on_battery: Callable[[Battery], None] | None = None
        self._reported: Battery | None = None

    @property
    def empty(self) -> bool:
        return self.level <= 0.0

    @property
    def changes_unwatched(self) -> bool:
        """Whether its charge can change with no drive to report it: it drains by the hour,
        or there is a charger to charge at. A battery that does neither (a fleet file
        without batteries) stays as it is until the robot drives, and needs no settling."""
        return bool(
            self.rates.idle_drain_per_h
            or self.rates.working_drain_per_h
            or (self.chargers and self.rates.charge_per_h)
        )

    @property
    def range_m(self) -> float:
        """How far the charge left drives (math.inf when driving does not drain it)."""
        return self.level / self.rates.drain_per_m if self.rates.drain_per_m else math.inf

    def reading(self) -> Battery:
        """The charge as a gauge reports it: whole percent, rounded up (0 is empty)."""
        percent = min(100, max(0, math.ceil(self.level - 1e-9)))
        return Battery(percent=percent, charging=self.charging)

    def watch(self, on_battery: Callable[[Battery], None]) -> None:
        self._on_battery = on_battery
        self._report()

    def settle(self) -> None:
        """Drain or charge for the time since the last settlement, then report a change."""
        now = self._clock.monotonic()
        hours, self._last = max(0.0, now - self._last) / 3600.0, now
        if self.charging:
            self.level = min(FULL, self.level + hours * self.rates.charge_per_h)
        else:
            drain = self.rates.working_drain_per_h if self.working else self.rates.idle_drain_per_h
            self.level = max(0.0, self.level - hours * drain)
        self.charging = not self.working and self.level < FULL and self._at_charger()
        self._report()

    def set_working(self, working: bool) -> None:
        """The robot starts (True) or ends (False) work: driving, or an arm at work."""
        self.settle()
        self.working = working
        self.settle()

    def drove(self, metres: float) -> None:
        """The robot drove `metres`."""
        if metres > 0.0 and self.rates.drain_per_m:
            left = self.level - metres * self.rates.drain_per_m
            # Driven to its range, it is empty (not a rounding error's worth above it).
            self.level = left if left > 1e-9 else 0.0
            self._report()

    def set_percent(self, percent: float) -> None:
        """Set the charge (`vahr fault THING battery PERCENT`)."""
        self.settle()
        self.level = max(0.0, min(FULL, percent))
        self.settle()

    def _at_charger(self) -> bool:
        if not self.chargers:
            return False
        pose = self._pose()
        return any(zone.pose.distance_to(pose) <= zone.radius for zone in self.chargers)

    def _report(self) -> None:
        reading = self.reading()
        if reading != self._reported and self._on_battery is not None:
            self._reported = reading
            self._on_battery(reading)


class BatteryTicker:
    """Settles every registered battery every `SETTLE_S` simulated seconds."""

    def __init__(self, *, clock: Clock, settle_s: float = SETTLE_S) -> None:
        self._clock = clock
        self._settle_s = settle_s
        self._batteries: dict[SimBattery, None] = {}
        self._task: asyncio.Task[None] | None = None

    def add(self, battery: SimBattery) -> None:
        self._batteries[battery] = None
        if self._task is None or self._task.done():
            self._task = asyncio.get_running_loop().create_task(self._run(), name="sim-battery")

    def discard(self, battery: SimBattery) -> None:
        self._batteries.pop(battery, None)
        if not self._batteries and self._task is not None:
            self._task.cancel()
            self._task = None

    async def _run(self) -> None:
        while self._batteries:
            await self._clock.sleep(self._settle_s)
            for battery in list(self._batteries):
                try:
                    battery.settle()
                except Exception:  # one robot's battery must not stop the others'
                    log.exception("settling a simulated battery failed")
