"""The dispatcher and the batteries: the energy rule (no task a robot cannot finish and
still reach a charger with its reserve), robots under the threshold charging by themselves
and announced, chargers held like tasks (two robots never take one), "send X to charge",
and robots taken out of service and put back.

The store is the local stack's SQLite store; the robots are `RobotState`s as a fleet index
reports them; what robots would receive is what the dispatcher published."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from tests.unit.dispatch.test_dispatch_core import Clock, Robots
from vahr.dispatch import Dispatcher, DispatchError, Order, RobotState, Task
from vahr.dispatch.energy import EnergyRule
from vahr.dispatch.ranking import STRAIGHT
from vahr.domain import Fleet
from vahr.local.task_store import SqliteTaskStore
from vahr.protocol import Battery

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.protocol import Command

# A line of zones: LOADING at 0, A at 10 m, FAR at 100 m, two chargers at -10 and 110 m.
# 1 % a metre keeps the sums easy; no drain by the hour.
FLOOR = """
battery:
  charge_below: 20
  reserve: 10
  charged: 90
  arm_time_s: 0
  types:
    standard: {drain_per_m: 1.0, idle_drain_per_h: 0, working_drain_per_h: 0}
robots:
  - {thing: ant, spoken: [ant], start: {x: 0.0, y: 0.0}}
  - {thing: bee, spoken: [bee], start: {x: 5.0, y: 0.0}}
  - {thing: cricket, spoken: [cricket], start: {x: 50.0, y: 0.0}}
zones:
  - {id: LOADING, spoken: [the dock], pose: {x: 0.0, y: 0.0}, arm: loader}
  - {id: A, spoken: [a], pose: {x: 10.0, y: 0.0}}
  - {id: FAR, spoken: [far], pose: {x: 100.0, y: 0.0}}
  - {id: WEST, spoken: [west charger], pose: {x: -10.0, y: 0.0}, charger: true}
  - {id: EAST, spoken: [east charger], pose: {x: 110.0, y: 0.0}, charger: true}
"""


@pytest.fixture
def floor() -> Fleet:
    return Fleet.from_yaml(FLOOR)


@pytest.fixture
def robots(floor: Fleet) -> Robots:
    robots = Robots(floor)
    for thing in floor.robot_things:
        robots.set(thing, battery=Battery(percent=100))
    return robots


@pytest.fixture
def store(tmp_path: Path) -> Iterator[SqliteTaskStore]:
    opened = SqliteTaskStore.in_state_dir(tmp_path)
    yield opened
    opened.close()


@pytest.fixture
def sent() -> list[tuple[str, Command]]:
    return []


@pytest.fixture
def charging() -> list[Task]:
    return []


@pytest.fixture
def dispatcher(
    floor: Fleet,
    store: SqliteTaskStore,
    robots: Robots,
    sent: list[tuple[str, Command]],
    charging: list[Task],
) -> Dispatcher:
    return Dispatcher(
        fleet=floor,
        store=store,
        candidates=robots,
        publish=lambda thing, command: sent.append((thing, command)),
        clock=Clock(),
        on_charging=charging.append,
    )


def state(thing: str, percent: int, **fields: object) -> RobotState:
    return RobotState(thing=thing, status="idle", battery=Battery(percent=percent), **fields)  # type: ignore[arg-type]


def test_the_energy_a_task_takes_is_its_way_then_the_way_to_the_nearest_charger(
    floor: Fleet,
) -> None:
    rule = EnergyRule(floor, STRAIGHT)
    task = Task(id="t", request="r", kind="navigate", zone="FAR", created_at="x")
    after = rule.after(task)
    assert after.metres == 10.0  # FAR to EAST
    # 30 m to FAR and 10 m to the charger: 40 %; at 50 % the reserve (10) is just kept.
    assert rule.needed("ant", 30.0, after) == 40.0
    assert rule.can_do(state("ant", 50), 30.0, after)
    assert not rule.can_do(state("ant", 49), 30.0, after)
    # Under the threshold, nothing; a robot without a battery report is not planned by it.
    assert not rule.can_do(state("ant", 19), 0.0, rule.after(task))
    assert rule.can_do(RobotState(thing="ant", status="idle"), 1e6, after)


def test_a_task_goes_to_a_farther_robot_when_the_nearest_could_not_finish_it(
    dispatcher: Dispatcher, robots: Robots, sent: list[tuple[str, Command]]
) -> None:
    # cricket is 50 m from FAR, ant 100 m: ant at 100 % could (100 + 10 + 10 reserve is
    # more than it has: no), cricket at 65 % can (50 + 10 = 60, 5 short of... 65 - 60 < 10).
    robots.set("cricket", battery=Battery(percent=70))
    robots.set("bee", battery=Battery(percent=100))
    given = dispatcher.submit(Order(zone="FAR"))
    assert [task.thing for task in given.assigned] == ["cricket"]
    robots.set("cricket", battery=Battery(percent=69))
    dispatcher.cancel(given.assigned[0].id)
    sent.clear()
    # Now nobody can: bee would need 95 + 10 = 105 %; the task waits, nothing is sent.
    again = dispatcher.submit(Order(zone="FAR"))
    assert again.assigned == [] and len(again.queued) == 1
    assert [thing for thing, command in sent if command.action == "navigate"] == []


def test_without_the_rule_the_nearest_robot_goes_whatever_its_charge(
    floor: Fleet, store: SqliteTaskStore, robots: Robots
) -> None:
    blind = Dispatcher(
        fleet=floor,
        store=store,
        candidates=robots,
        publish=lambda thing, command: None,
        clock=Clock(),
        respect_battery=False,
    )
    robots.set("cricket", battery=Battery(percent=21))
    assert [task.thing for task in blind.submit(Order(zone="FAR")).assigned] == ["cricket"]


def test_an_idle_robot_under_the_threshold_goes_to_the_nearest_charger_and_is_announced(
    dispatcher: Dispatcher,
    robots: Robots,
    sent: list[tuple[str, Command]],
    charging: list[Task],
) -> None:
    low = robots.set("cricket", battery=Battery(percent=12))
    task = dispatcher.observe(low)
    assert task is not None and task.kind == "charge" and task.zone == "EAST"
    assert [(thing, command.id) for thing, command in sent] == [("cricket", task.id)]
    assert sent[0][1].action == "navigate" and sent[0][1].params.zone == "EAST"  # type: ignore[union-attr]
    assert charging == [task]
    # It takes no task while it charges, though it is nearest.
    given = dispatcher.submit(Order(zone="FAR"))
    assert "cricket" not in [t.thing for t in given.assigned]
    # Arrived and charging: still held, until charged.
    at_dock = robots.set(
        "cricket",
        zone="EAST",
        last_command_id=task.id,
        last_result="done",
        battery=Battery(percent=50, charging=True),
    )
    assert dispatcher.observe(at_dock) is None
    assert dispatcher.store.get(task.id).status == "assigned"  # type: ignore[union-attr]
    charged = robots.set("cricket", battery=Battery(percent=90, charging=True))
    dispatcher.observe(charged)
    assert dispatcher.store.get(task.id).status == "done"  # type: ignore[union-attr]


def test_two_robots_never_take_one_charger(
    dispatcher: Dispatcher, robots: Robots, charging: list[Task]
) -> None:
    first = dispatcher.observe(robots.set("ant", battery=Battery(percent=10)))
    second = dispatcher.observe(robots.set("bee", battery=Battery(percent=10)))
    assert first is not None and second is not None
    assert (first.zone, second.zone) == ("WEST", "EAST")
    # Both taken: a third low robot waits (its next report asks again), announced never.
    assert dispatcher.observe(robots.set("cricket", battery=Battery(percent=10))) is None
    assert len(charging) == 2


def test_a_later_claim_on_a_charger_gives_way_to_an_earlier_one(
    dispatcher: Dispatcher, store: SqliteTaskStore
) -> None:
    # Another dispatcher wrote its claim on WEST first (a race): this one takes EAST.
    store.add(
        Task(
            id="rival",
            request="r",
            kind="charge",
            zone="WEST",
            robots=["bee"],
            created_at="2000-01-01T00:00:00.000000Z",
        )
    )
    taken = dispatcher.charge("ant", asked=True)
    assert taken is not None and taken.zone == "EAST"


def test_send_a_robot_to_charge_now_puts_its_task_back_in_the_queue(
    dispatcher: Dispatcher, robots: Robots, sent: list[tuple[str, Command]]
) -> None:
    held = dispatcher.submit(Order(zone="A")).assigned[0]
    assert held.thing == "bee"
    task = dispatcher.charge("bee", asked=True)
    assert task is not None and task.zone == "WEST"
    assert [thing for thing, _ in sent[-2:]] == ["bee", "ant"]  # to the charger; the task to ant
    again = dispatcher.store.get(held.id)
    assert again is not None and again.status == "assigned" and again.thing == "ant"


def test_send_to_charge_says_why_not(dispatcher: Dispatcher, robots: Robots) -> None:
    with pytest.raises(DispatchError) as unknown:
        dispatcher.charge("moth", asked=True)
    assert unknown.value.code == "unknown_robot"
    robots.set("bee", in_service=False)
    with pytest.raises(DispatchError) as out:
        dispatcher.charge("bee", asked=True)
    assert out.value.code == "out_of_service"
    dispatcher.charge("ant", asked=True)
    dispatcher.charge("cricket", asked=True)
    robots.set("bee", in_service=True)
    with pytest.raises(DispatchError) as none:
        dispatcher.charge("bee", asked=True)
    assert none.value.code == "no_charger"


def test_a_robot_out_of_service_gives_its_task_back_stops_and_takes_none(
    dispatcher: Dispatcher, robots: Robots, sent: list[tuple[str, Command]]
) -> None:
    held = dispatcher.submit(Order(zone="A")).assigned[0]
    assert held.thing == "bee"
    robots.set("bee", in_service=False)
    change = dispatcher.withdrawn("bee")
    assert ("bee", "stop") in [(thing, command.action) for thing, command in sent]
    assert [task.thing for task in change.reassigned] == ["ant"]
    # Nearest to zone A, yet not picked; its own group task waits for it.
    assert dispatcher.submit(Order(zone="A")).assigned[0].thing == "cricket"
    only_bee = Task(
        id="mine", request="r", kind="navigate", zone="A", robots=["bee"], created_at="2030"
    )
    dispatcher.store.add(only_bee)
    assert dispatcher.observe(robots.states["bee"]) is None
    robots.set("bee", in_service=True)
    back = dispatcher.reinstated("bee")
    assert [task.id for task in back.given] == ["mine"]
