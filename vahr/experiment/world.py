"""The experiment floor, built from `fleet.yaml`: zones, arms, packages and the LED.

The loading zone has a conveyor and an arm that loads a robot; every delivery zone has an
arm that unloads it. Task III's success LED lights when both robots have delivered to zone
D in order (the judge's own rule, `score_goal`), and stays off otherwise. The world is driven
by the robots' events; what changes is returned so the session runner can log it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from vahr.experiment.judge import Delivery, score_goal

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.experiment.tasks import TaskGoal


@dataclass
class Arm:
    """An arm at a zone: the loader at LOADING, an unloader at each delivery zone."""

    zone: str
    role: str
    handled: int = 0


@dataclass
class World:
    """The state of the floor as the experiment sees it."""

    arms: dict[str, Arm]
    packages: dict[str, list[str]] = field(default_factory=dict)  # zone -> robots unloaded
    cargo: dict[str, bool] = field(default_factory=dict)
    led_on: bool = False
    _led_goal: TaskGoal | None = None
    _led_deliveries: list[Delivery] = field(default_factory=list)
    _seq: int = 0

    @classmethod
    def from_fleet(cls, fleet: Fleet) -> World:
        arms = {zone.id: Arm(zone.id, zone.arm) for zone in fleet.zones if zone.arm is not None}
        return cls(
            arms=arms,
            packages={zone.id: [] for zone in fleet.zones if zone.arm == "unloader"},
            cargo={thing: False for thing in fleet.robot_things},
        )

    def arm_led(
        self, goal: TaskGoal, deliveries: list[Delivery] | None = None
    ) -> list[dict[str, Any]]:
        """Watch for `goal` (task III): the LED is off until the goal succeeds.

        `deliveries` are those already made in the task (when a session resumes).
        """
        self._led_goal = goal
        self._led_deliveries = list(deliveries or [])
        if deliveries and score_goal(goal, self._led_deliveries).success:
            return self._set_led(True, "resumed after success")
        self._seq = max((d.seq for d in self._led_deliveries), default=self._seq)
        return self._set_led(False, "armed for task " + goal.task)

    def disarm_led(self) -> None:
        self._led_goal = None

    def apply(self, event: dict[str, Any], *, for_task: bool = True) -> list[dict[str, Any]]:
        """Apply one robot event (as on the wire); return the world changes it caused.

        `for_task` is False for a delivery completing an earlier task's command: the arm
        still unloads it, but it does not count towards the LED.
        """
        self._seq += 1
        kind, thing, zone = event.get("event"), str(event.get("thing")), event.get("zone")
        changes: list[dict[str, Any]] = []
        if kind == "loaded":
            self.cargo[thing] = True
            arm = self.arms.get(str(zone))
            if arm is not None:
                arm.handled += 1
            changes.append({"what": "loaded", "thing": thing, "zone": zone, "arm": "loader"})
        elif kind == "delivered":
            self.cargo[thing] = False
            arm = self.arms.get(str(zone))
            if arm is not None:
                arm.handled += 1
            self.packages.setdefault(str(zone), []).append(thing)
            changes.append({"what": "unloaded", "thing": thing, "zone": zone, "arm": "unloader"})
            if self._led_goal is not None and for_task:
                self._led_deliveries.append(Delivery(thing, zone, self._seq))
                verdict = score_goal(self._led_goal, self._led_deliveries)
                if verdict.success and not self.led_on:
                    changes += self._set_led(True, verdict.reason)
        return changes

    def _set_led(self, on: bool, why: str) -> list[dict[str, Any]]:
        self.led_on = on
        return [{"what": "led", "on": on, "why": why}]

    def snapshot(self) -> dict[str, Any]:
        return {
            "led_on": self.led_on,
            "packages": {zone: list(things) for zone, things in self.packages.items()},
            "cargo": dict(self.cargo),
        }
