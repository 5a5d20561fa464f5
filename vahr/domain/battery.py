"""How a fleet's batteries behave: the fleet file's `battery:` section (a contract).

A fleet that models its batteries says, once for the fleet, when a robot goes to charge
(`charge_below`), the charge no task may leave it under (`reserve`) and when a charging
robot is back in the pool (`charged`), and, per robot type (a robot's `type:`), how fast a
battery drains by the metre driven and by the hour (idle, or working: driving and at an
arm) and how fast it charges at a zone with `charger: true`. The simulator drains and
charges by these rates; the dispatcher plans with them (`vahr.dispatch.energy`).

A fleet file without the section has batteries that never drain (its robots still report
their charge, full): it has no chargers to send them to. The defaults are those of a
typical indoor delivery robot: about eight hours of work on a charge, two hours to charge.
"""

from __future__ import annotations

from typing import Annotated

import msgspec

Percent = Annotated[float, msgspec.Meta(ge=0, le=100)]
Rate = Annotated[float, msgspec.Meta(ge=0, le=10_000)]

# The robot type of a robot whose entry names none.
DEFAULT_TYPE = "standard"
# Seconds an arm takes to load or unload (the simulator's default), the time at the arms
# a delivery spends working.
ARM_TIME_S = 6.0


class BatteryType(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """How one type of robot's battery drains and charges, in percent of a full charge."""

    # Percent per metre driven (0.005: 200 m drive one percent).
    drain_per_m: Rate = 0.005
    # Percent per hour standing idle, and per hour working (driving, loading, unloading).
    idle_drain_per_h: Rate = 2.0
    working_drain_per_h: Rate = 4.0
    # Percent per hour gained at a charger.
    charge_per_h: Rate = 50.0

    @property
    def drains(self) -> bool:
        return bool(self.drain_per_m or self.idle_drain_per_h or self.working_drain_per_h)


NO_DRAIN = BatteryType(drain_per_m=0.0, idle_drain_per_h=0.0, working_drain_per_h=0.0)


class BatteryPlan(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The fleet's battery rules (`battery:` in the fleet file)."""

    # An idle robot under this charge goes to the nearest free charger by itself.
    charge_below: Percent = 20.0
    # No task is given that would leave a robot under this charge at a charger after it.
    reserve: Percent = 10.0
    # A charging robot takes tasks again from this charge on.
    charged: Percent = 90.0
    # Drain and charge rates by robot type; a type not listed has the defaults.
    types: dict[str, BatteryType] = {}
    # Seconds of arm work in a delivery (loading and unloading), counted as working time.
    arm_time_s: Annotated[float, msgspec.Meta(ge=0, le=3600)] = ARM_TIME_S
    # The speed the dispatcher assumes to count the time a drive works (the simulator's).
    drive_speed_mps: Annotated[float, msgspec.Meta(gt=0, le=20)] = 0.5

    def rates(self, robot_type: str) -> BatteryType:
        """The rates of robots of `robot_type` (the defaults for a type not listed)."""
        return self.types.get(robot_type) or _DEFAULT_RATES


_DEFAULT_RATES = BatteryType()
