"""The core's battery rule for a host that does not see every report (the dispatcher
Lambda): which robots a fleet search may stop at (`Dispatcher.usable`) and the idle low
robots sent to charge from a list of robots (`Dispatcher.charge_low`), with what a robot
would receive. The store is the local SQLite one; the robots are `RobotState`s."""

from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec
import pytest

from tests.unit.dispatch.test_dispatch_battery import FLOOR, state
from tests.unit.dispatch.test_dispatch_core import Clock, Robots
from vahr.dispatch import Dispatcher
from vahr.domain import Fleet
from vahr.local.task_store import SqliteTaskStore
from vahr.protocol import Battery

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.dispatch import Task
    from vahr.protocol import Command


class Fleet3:
    """The battery checks' floor: three robots, full, two chargers; what they received."""

    def __init__(self, store: SqliteTaskStore) -> None:
        floor = Fleet.from_yaml(FLOOR)
        self.robots = Robots(floor)
        for thing in floor.robot_things:
            self.robots.set(thing, battery=Battery(percent=100))
        self.sent: list[tuple[str, Command]] = []
        self.charging: list[Task] = []
        self.dispatcher = Dispatcher(
            fleet=floor,
            store=store,
            candidates=self.robots,
            publish=lambda thing, command: self.sent.append((thing, command)),
            clock=Clock(),
            on_charging=self.charging.append,
        )


@pytest.fixture
def fleet(tmp_path: Path) -> Iterator[Fleet3]:
    store = SqliteTaskStore.in_state_dir(tmp_path)
    yield Fleet3(store)
    store.close()


def test_a_robot_too_low_for_any_task_or_out_of_service_is_not_usable(fleet: Fleet3) -> None:
    dispatcher = fleet.dispatcher
    assert dispatcher.usable(state("ant", 20))
    # Under charge_below (20), charging or not, it takes no task: a search reads past it
    assert not dispatcher.usable(state("ant", 19))
    charging_low = msgspec.structs.replace(
        state("ant", 19), battery=Battery(percent=19, charging=True)
    )
    assert not dispatcher.usable(charging_low)
    assert not dispatcher.usable(state("ant", 100, in_service=False))
    # Ignoring batteries, every robot in service is
    dispatcher.respect_battery = False
    assert dispatcher.usable(state("ant", 1))


def test_the_idle_low_robots_go_to_the_nearest_free_charger_once(fleet: Fleet3) -> None:
    dispatcher, robots, sent = fleet.dispatcher, fleet.robots, fleet.sent
    # ant by WEST at 10 %, bee at 15 % out of service, cricket working at 5 %
    ant = robots.set("ant", battery=Battery(percent=10))
    bee = robots.set("bee", battery=Battery(percent=15), in_service=False)
    cricket = robots.set("cricket", battery=Battery(percent=5), status="navigating")
    given = dispatcher.charge_low([ant, bee, cricket])
    # Then only ant goes, to WEST, announced
    assert [(task.thing, task.kind, task.zone) for task in given] == [("ant", "charge", "WEST")]
    assert [(thing, command.action) for thing, command in sent] == [("ant", "navigate")]
    assert fleet.charging == given
    # And asked again, a robot holding its charge task is not sent twice
    assert dispatcher.charge_low([ant]) == []
    assert len(sent) == 1
