"""The energy rule: whether a robot's battery can do a task and still reach a charger with
its reserve left, and when a robot should charge (docs/dispatch.md, "Battery").

The charge a task takes is the way it drives (from the robot to the pickup and the drop,
the dispatcher's path length) and then the way from the drop to the nearest charger, by
the metre (`drain_per_m` of the robot's type), plus the working time: those metres at
`drive_speed_mps` and the arms' time of a delivery (`arm_time_s`), by the hour
(`working_drain_per_h`). A robot may take the task when its charge less that is at least
the fleet's `reserve`. A robot under `charge_below` takes no task: it charges first.

Pure: both hosts (`vahr up`'s dispatcher and the dispatcher Lambda) decide with it. A
robot that reports no battery, or whose battery never drains, is not planned by it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from vahr.dispatch.ranking import RobotState, Routes
    from vahr.dispatch.tasks import Task
    from vahr.domain.fleet import Fleet, Zone


@dataclass(frozen=True)
class After:
    """What a task costs beyond the robot's own way to it: the metres from its drop to the
    nearest charger and the seconds at the arms."""

    metres: float
    arm_s: float


class EnergyRule:
    """The rule on one fleet's floor with some zones closed (`routes`)."""

    def __init__(self, fleet: Fleet, routes: Routes) -> None:
        self.fleet = fleet
        self.routes = routes
        self.plan = fleet.battery_plan
        self._to_charger: dict[str, float] = {}

    def to_charger(self, zone: Zone) -> float:
        """Metres from `zone` to the nearest charger (math.inf with none reachable)."""
        known = self._to_charger.get(zone.id)
        if known is None:
            known = min(
                (
                    self.routes.field(charger).distance(zone.pose.x, zone.pose.y)
                    for charger in self.fleet.chargers
                ),
                default=math.inf,
            )
            self._to_charger[zone.id] = known
        return known

    def after(self, task: Task) -> After:
        arm_s = self.plan.arm_time_s if task.pickup is not None else 0.0
        return After(self.to_charger(self.fleet.zone(task.zone)), arm_s)

    def needed(self, thing: str, metres: float, after: After) -> float:
        """Percent of a charge `thing` uses to drive `metres`, do the task and reach a
        charger after it."""
        rates = self.fleet.battery_rates(thing)
        driven = metres + after.metres
        working_h = (driven / self.plan.drive_speed_mps + after.arm_s) / 3600.0
        return driven * rates.drain_per_m + working_h * rates.working_drain_per_h

    def can_do(self, robot: RobotState, metres: float, after: After) -> bool:
        """Whether `robot`, `metres` from the task's end by its way there, may take it."""
        if not self.takes_tasks(robot):
            return False
        battery = robot.battery
        if battery is None or not self.fleet.battery_rates(robot.thing).drains:
            return True
        return battery.percent - self.needed(robot.thing, metres, after) >= self.plan.reserve

    def takes_tasks(self, robot: RobotState) -> bool:
        """Whether `robot` may take any task at all: not under the fleet's `charge_below`
        (charging or not), or not planned by the rule. What a search for free robots reads
        past (the dispatcher Lambda's fleet search)."""
        battery = robot.battery
        if battery is None or not self.fleet.battery_rates(robot.thing).drains:
            return True
        return battery.percent >= self.plan.charge_below

    def wants_charge(self, robot: RobotState) -> bool:
        """Under the fleet's threshold and not charging: it should go to a charger."""
        battery = robot.battery
        return (
            battery is not None
            and not battery.charging
            and battery.percent < self.plan.charge_below
            and self.fleet.battery_rates(robot.thing).drains
        )

    def charged(self, robot: RobotState) -> bool:
        """Charged enough to take tasks again (`charged`), or full."""
        battery = robot.battery
        return battery is None or battery.percent >= min(self.plan.charged, 100.0)
