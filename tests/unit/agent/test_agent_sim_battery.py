"""The simulated battery: it drains by the metre and by the hour, idle and working, charges
at a charging zone, is reported in whole percent when that changes, and a robot whose
battery is empty stops where it is."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from robot_agent.backends.port import NavigationFailed
from robot_agent.backends.sim import SimBackend
from robot_agent.backends.sim_battery import BatteryTicker, SimBattery
from robot_agent.clock import ScaledClock
from robot_agent.config import SimSettings
from vahr.domain import Pose, Zone, load_fleet
from vahr.domain.battery import NO_DRAIN, BatteryType
from vahr.protocol import Battery

FLEET = load_fleet(Path(__file__).parents[2] / "fleets" / "three_rovers.yaml")


class Clock:
    """A clock the test moves by hand."""

    def __init__(self) -> None:
        self.now = 0.0

    def monotonic(self) -> float:
        return self.now


def battery(clock: Clock, pose: Pose, **rates: float) -> tuple[SimBattery, list[Battery]]:
    seen: list[Battery] = []
    cell = SimBattery(
        clock=clock,  # type: ignore[arg-type]
        pose=lambda: pose,
        rates=BatteryType(**rates),
        chargers=FLEET.chargers,
    )
    cell.watch(seen.append)
    return cell, seen


def test_idle_and_working_drain_by_the_hour_and_driving_by_the_metre() -> None:
    clock = Clock()
    cell, seen = battery(clock, Pose(0, 0), idle_drain_per_h=2, working_drain_per_h=10)
    assert seen == [Battery(percent=100, charging=False)]
    clock.now = 3600.0
    cell.settle()
    assert cell.reading() == Battery(percent=98, charging=False)
    cell.set_working(True)
    clock.now = 7200.0
    cell.set_working(False)
    assert round(cell.level, 6) == 88.0
    cell.drove(100.0)  # the default 0.005 % a metre
    assert round(cell.level, 6) == 87.5
    # Reported only when the whole percent changes: 100, 98, 88.
    assert [reading.percent for reading in seen] == [100, 98, 88]


def test_a_robot_standing_at_a_charger_charges_up_to_full_then_stops_charging() -> None:
    clock = Clock()
    dock = FLEET.zone("DOCK").pose
    cell, seen = battery(clock, dock, charge_per_h=50)
    cell.set_percent(40)
    assert seen[-1] == Battery(percent=40, charging=True)
    clock.now = 1800.0
    cell.settle()
    assert seen[-1] == Battery(percent=65, charging=True)
    clock.now = 3 * 3600.0
    cell.settle()
    assert seen[-1] == Battery(percent=100, charging=False)


def test_away_from_a_charger_it_does_not_charge() -> None:
    clock = Clock()
    cell, seen = battery(clock, Pose(1, 1), charge_per_h=50)
    cell.set_percent(40)
    clock.now = 3600.0
    cell.settle()
    assert seen[-1].charging is False
    assert seen[-1].percent < 40


async def test_a_simulated_robot_drains_as_it_drives_and_stops_when_empty() -> None:
    clock = ScaledClock(400.0)
    robot = SimBackend(
        start=Pose(1.0, 1.0),
        clock=clock,
        settings=SimSettings(speed_mps=1.0, tick_s=0.1),
        battery=BatteryType(drain_per_m=1.0, idle_drain_per_h=0, working_drain_per_h=0),
    )
    seen: list[Battery] = []
    robot.watch_battery(seen.append)
    await robot.go_to(FLEET.zone("A"), lambda progress: None)  # about 3 m
    assert 96 <= seen[-1].percent <= 97
    robot.set_battery(2.0)
    with pytest.raises(NavigationFailed, match="the battery is empty"):
        await robot.go_to(FLEET.zone("B"), lambda progress: None)  # 7 m: stops after 2
    assert seen[-1].percent == 0
    stopped = robot.pose
    assert 1.5 < stopped.distance_to(FLEET.zone("A").pose) < 2.6
    with pytest.raises(NavigationFailed, match="the battery is empty"):
        await robot.go_to(FLEET.zone("A"), lambda progress: None)
    assert robot.pose == stopped
    await robot.close()
    await asyncio.sleep(0)


class CountingTicker(BatteryTicker):
    """A battery ticker that remembers what it was given to settle."""

    def __init__(self) -> None:
        super().__init__(clock=ScaledClock(1.0))
        self.settled: list[SimBattery] = []

    def add(self, battery: SimBattery) -> None:
        self.settled.append(battery)
        super().add(battery)


@pytest.mark.parametrize(
    ("rates", "chargers", "settled"),
    [
        (NO_DRAIN, (), False),  # a fleet file without batteries: the charge never changes
        (NO_DRAIN, FLEET.chargers, True),  # set below full by a fault, it charges at one
        (BatteryType(drain_per_m=0.0, working_drain_per_h=0.0), (), True),  # idle drain
        (BatteryType(drain_per_m=0.0, idle_drain_per_h=0.0), (), True),  # working drain
    ],
)
async def test_only_a_battery_whose_charge_can_change_standing_is_settled(
    rates: BatteryType, chargers: tuple[Zone, ...], settled: bool
) -> None:
    ticker = CountingTicker()
    robot = SimBackend(
        start=Pose(1.0, 1.0),
        clock=ScaledClock(1.0),
        battery=rates,
        chargers=chargers,
        battery_ticker=ticker,
    )
    seen: list[Battery] = []
    robot.watch_battery(seen.append)
    assert seen == [Battery(percent=100, charging=False)]
    assert bool(ticker.settled) is settled
    await robot.close()
    await asyncio.sleep(0)
