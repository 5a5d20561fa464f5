"""The dispatch core on a made-up floor: the cost, the ranking, orders, the queue and races.

The store is the local stack's real SQLite store (in a temporary directory); the robots are
`RobotState`s as a fleet index reports them; what the robots would receive is what the
dispatcher published.
"""

from __future__ import annotations

import threading
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING

import pytest

from vahr.dispatch import (
    Dispatcher,
    DispatchError,
    Order,
    RobotState,
    Task,
    rank,
    task_cost,
)
from vahr.domain import Fleet, Pose
from vahr.local.task_store import SqliteTaskStore

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.protocol import Command

# A made-up floor: LOADING at the origin, zone FAR 30 m east, zone NEAR 3 m north; robots
# spread so that distances are easy to add up by hand.
FLOOR = """
robots:
  - {thing: ant, spoken: [ant], start: {x: 0.0, y: 10.0}}
  - {thing: bee, spoken: [bee], start: {x: 20.0, y: 0.0}}
  - {thing: cricket, spoken: [cricket], start: {x: 0.0, y: -10.0}}
  - {thing: dragonfly, spoken: [dragonfly], start: {x: 36.0, y: 0.0}}
zones:
  - {id: LOADING, spoken: [the dock], pose: {x: 0.0, y: 0.0}, arm: loader}
  - {id: FAR, spoken: [far], pose: {x: 30.0, y: 0.0}}
  - {id: NEAR, spoken: [near], pose: {x: 0.0, y: 3.0}}
groups:
  - {id: flyers, spoken: [the flyers], robots: [bee, dragonfly]}
"""


@pytest.fixture
def floor() -> Fleet:
    return Fleet.from_yaml(FLOOR)


class Robots:
    """The `Candidates` port over a dict, as a fleet index answers it."""

    def __init__(self, fleet: Fleet) -> None:
        self.states = {
            robot.thing: RobotState(thing=robot.thing, status="idle", pose=robot.start)
            for robot in fleet.robots
        }

    def set(self, thing: str, **changes: object) -> RobotState:
        current = self.states[thing]
        fields = {name: getattr(current, name) for name in current.__struct_fields__}
        self.states[thing] = RobotState(**{**fields, **changes})  # type: ignore[arg-type]
        return self.states[thing]

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        return [
            state
            for state in self.states.values()
            if state.available and (zone is None or state.zone == zone)
        ]

    def state(self, thing: str) -> RobotState | None:
        return self.states.get(thing)


class Clock:
    def __init__(self) -> None:
        self.now = datetime(2026, 11, 26, 12, 0, tzinfo=UTC)

    def __call__(self) -> datetime:
        self.now += timedelta(seconds=1)
        return self.now


@pytest.fixture
def robots(floor: Fleet) -> Robots:
    return Robots(floor)


@pytest.fixture
def store(tmp_path: Path) -> Iterator[SqliteTaskStore]:
    opened = SqliteTaskStore.in_state_dir(tmp_path)
    yield opened
    opened.close()


@pytest.fixture
def sent() -> list[tuple[str, Command]]:
    return []


@pytest.fixture
def dispatcher(
    floor: Fleet, store: SqliteTaskStore, robots: Robots, sent: list[tuple[str, Command]]
) -> Dispatcher:
    return Dispatcher(
        fleet=floor,
        store=store,
        candidates=robots,
        publish=lambda thing, command: sent.append((thing, command)),
        clock=Clock(),
    )


def _task(kind: str, zone: str) -> Task:
    return Task(
        id="t",
        request="r",
        kind=kind,  # type: ignore[arg-type]
        zone=zone,
        pickup="LOADING" if kind == "deliver" else None,
        created_at="2026-11-26T12:00:00.000000Z",
    )


# --- the cost ---------------------------------------------------------------------------


def test_delivery_cost_is_the_path_to_the_pickup_then_to_the_drop(floor: Fleet) -> None:
    # (0,10) -> dock (0,0): 10 m; dock -> FAR (30,0): 30 m.
    assert task_cost(floor, Pose(0.0, 10.0), _task("deliver", "FAR")) == pytest.approx(40.0)
    # (3,4) -> dock: 5 m; dock -> NEAR: 3 m.
    assert task_cost(floor, Pose(3.0, 4.0), _task("deliver", "NEAR")) == pytest.approx(8.0)


def test_navigation_cost_is_the_path_to_the_zone(floor: Fleet) -> None:
    assert task_cost(floor, Pose(0.0, 10.0), _task("navigate", "FAR")) == pytest.approx(
        (30.0**2 + 10.0**2) ** 0.5
    )
    assert task_cost(floor, Pose(30.0, 0.0), _task("navigate", "FAR")) == 0.0


def test_the_cheapest_robot_gets_a_delivery_though_another_is_nearer_the_drop(
    floor: Fleet, robots: Robots
) -> None:
    # dragonfly stands 6 m from FAR but 36 m from the dock: 66 m in all; ant 10 + 30 = 40.
    ranked = rank(floor, _task("deliver", "FAR"), robots.available())
    assert [robot.thing for robot in ranked] == ["ant", "cricket", "bee", "dragonfly"]
    # To navigate to FAR, the nearest robot goes first.
    ranked = rank(floor, _task("navigate", "FAR"), robots.available())
    assert ranked[0].thing == "dragonfly"


def test_idle_robots_rank_before_busy_ones_whatever_the_distance(
    floor: Fleet, robots: Robots
) -> None:
    robots.set("dragonfly", status="navigating")
    ranked = rank(floor, _task("navigate", "FAR"), robots.available())
    assert [robot.thing for robot in ranked][-1] == "dragonfly"


def test_equal_costs_are_broken_by_thing_name_whatever_the_order_given(
    floor: Fleet, robots: Robots
) -> None:
    robots.set("ant", pose=Pose(0.0, 5.0))
    robots.set("cricket", pose=Pose(0.0, -5.0))
    available = robots.available()
    for order in (available, list(reversed(available))):
        ranked = rank(floor, _task("deliver", "NEAR"), order)
        assert [robot.thing for robot in ranked][:2] == ["ant", "cricket"]
    assert [r.thing for r in rank(floor, _task("deliver", "NEAR"), available, limit=1)] == ["ant"]


def test_stuck_and_offline_robots_are_never_candidates(robots: Robots) -> None:
    robots.set("ant", status="stuck")
    robots.set("bee", connected=False)
    assert {robot.thing for robot in robots.available()} == {"cricket", "dragonfly"}


# --- orders -----------------------------------------------------------------------------


def test_a_delivery_goes_to_the_best_robot_and_it_is_told_so(
    dispatcher: Dispatcher, sent: list[tuple[str, Command]]
) -> None:
    result = dispatcher.submit(Order(kind="deliver", zone="FAR"))
    assert [task.thing for task in result.assigned] == ["ant"]
    assert result.queued == []
    [(thing, command)] = sent
    assert thing == "ant"
    assert command.action == "deliver"
    assert command.params.zone == "FAR"  # type: ignore[union-attr]
    assert command.id == result.assigned[0].id


def test_two_robots_go_to_a_zone_and_a_third_is_queued_when_only_two_are_free(
    dispatcher: Dispatcher, robots: Robots
) -> None:
    robots.set("ant", status="stuck")
    robots.set("bee", connected=False)
    result = dispatcher.submit(Order(zone="NEAR", count=3))
    assert sorted(task.thing or "" for task in result.assigned) == ["cricket", "dragonfly"]
    assert len(result.queued) == 1
    assert result.positions == [1]


def test_with_every_robot_busy_a_task_is_queued_and_told_its_place(
    dispatcher: Dispatcher, robots: Robots
) -> None:
    dispatcher.submit(Order(zone="NEAR", count=4))
    first = dispatcher.submit(Order(kind="deliver", zone="FAR"))
    second = dispatcher.submit(Order(kind="deliver", zone="NEAR"))
    assert first.assigned == [] and first.positions == [1]
    assert second.positions == [2]
    assert [task.zone for task in dispatcher.pending()] == ["FAR", "NEAR"]


def test_a_freed_robot_takes_the_first_queued_task(
    dispatcher: Dispatcher, robots: Robots, sent: list[tuple[str, Command]]
) -> None:
    held = {}
    for _ in range(4):
        [task] = dispatcher.submit(Order(zone="NEAR")).assigned
        held[task.thing] = task
    queued = dispatcher.submit(Order(kind="deliver", zone="FAR")).queued[0]
    dispatcher.submit(Order(kind="deliver", zone="NEAR"))
    # bee acknowledges, then finishes its task.
    bee_task = held["bee"]
    assert (
        dispatcher.observe(robots.set("bee", last_command_id=bee_task.id, last_result="accepted"))
        is None
    )
    taken = dispatcher.observe(
        robots.set("bee", last_command_id=bee_task.id, last_result="done", status="idle")
    )
    assert taken is not None and taken.id == queued.id and taken.thing == "bee"
    assert dispatcher.store.get(bee_task.id).status == "done"  # type: ignore[union-attr]
    assert sent[-1][0] == "bee" and sent[-1][1].id == queued.id
    assert [task.zone for task in dispatcher.pending()] == ["NEAR"]


def test_a_group_sends_each_member_and_a_busy_member_goes_when_it_frees(
    dispatcher: Dispatcher, robots: Robots
) -> None:
    [bees_task] = dispatcher.submit(Order(zone="NEAR", count=1, group="flyers")).assigned
    assert bees_task.thing in ("bee", "dragonfly")
    result = dispatcher.submit(Order(zone="FAR", group="flyers"))
    assert len(result.assigned) == 1 and len(result.queued) == 1
    waiting = result.queued[0]
    assert waiting.robots == [bees_task.thing]
    # Other robots freeing do not take a member's task.
    assert dispatcher.robot_freed("ant") is None


def test_robots_in_a_zone_go_and_nothing_is_queued(dispatcher: Dispatcher, robots: Robots) -> None:
    robots.set("ant", zone="NEAR")
    robots.set("cricket", zone="NEAR")
    result = dispatcher.submit(Order(zone="LOADING", origin="NEAR"))
    assert sorted(task.thing or "" for task in result.assigned) == ["ant", "cricket"]
    with pytest.raises(DispatchError, match="no robot in zone FAR is free"):
        dispatcher.submit(Order(zone="LOADING", origin="FAR"))


def test_every_idle_robot_leaves_busy_ones_alone(
    dispatcher: Dispatcher, robots: Robots, sent: list[tuple[str, Command]]
) -> None:
    robots.set("bee", status="navigating")
    result = dispatcher.submit(Order(zone="FAR", idle=True))
    assert sorted(task.thing or "" for task in result.assigned) == ["ant", "cricket", "dragonfly"]
    assert "bee" not in [thing for thing, _ in sent]


@pytest.mark.parametrize(
    ("order", "message"),
    [
        (Order(zone="MARS"), "there is no zone 'MARS'; zones are LOADING, FAR, NEAR"),
        (Order(zone="FAR", group="swimmers"), "there is no group 'swimmers'; groups are flyers"),
        (Order(zone="FAR", count=5), "the fleet has 4 robots; 5 cannot go"),
        (Order(zone="FAR", count=0), "at least one robot"),
    ],
)
def test_a_bad_order_is_one_line_and_stores_nothing(
    dispatcher: Dispatcher, order: Order, message: str, sent: list[tuple[str, Command]]
) -> None:
    with pytest.raises(DispatchError, match=message.replace("(", r"\(")):
        dispatcher.submit(order)
    assert dispatcher.tasks() == [] and sent == []


def test_cancelling_a_queued_task_removes_it_and_an_assigned_one_stops_its_robot(
    dispatcher: Dispatcher, sent: list[tuple[str, Command]]
) -> None:
    assigned = dispatcher.submit(Order(zone="FAR", count=4)).assigned
    queued = dispatcher.submit(Order(zone="NEAR")).queued[0]
    assert dispatcher.cancel(queued.id) is not None
    assert dispatcher.pending() == []
    assert dispatcher.cancel(queued.id) is None  # already over
    dispatcher.submit(Order(kind="deliver", zone="NEAR"))  # queued
    victim = assigned[0]
    dispatcher.cancel(victim.id)
    stops = [thing for thing, command in sent if command.action == "stop"]
    assert stops == [victim.thing]
    # The stopped robot is free again and takes the queued delivery.
    assert sent[-1][0] == victim.thing and sent[-1][1].action == "deliver"


def test_a_robot_that_takes_a_command_by_name_gives_its_task_up(
    dispatcher: Dispatcher, robots: Robots
) -> None:
    [task] = dispatcher.submit(Order(zone="FAR")).assigned
    assert task.thing is not None
    dispatcher.observe(robots.set(task.thing, last_command_id=task.id, last_result="accepted"))
    dispatcher.observe(robots.set(task.thing, last_command_id="by-name", last_result="accepted"))
    assert dispatcher.store.get(task.id).outcome == "preempted"  # type: ignore[union-attr]


def test_a_task_given_up_for_a_command_by_name_is_told_not_dropped(
    dispatcher: Dispatcher, robots: Robots
) -> None:
    told: list[Task] = []
    dispatcher.on_given_up = told.append
    # Given a delivery a robot acknowledged
    [task] = dispatcher.submit(Order(kind="deliver", zone="FAR")).assigned
    assert task.thing is not None
    dispatcher.observe(robots.set(task.thing, last_command_id=task.id, last_result="accepted"))
    assert told == []
    # When the robot is sent elsewhere by name
    dispatcher.observe(robots.set(task.thing, last_command_id="by-name", last_result="accepted"))
    # Then the task given up is handed on to be announced, once
    assert [(t.id, t.thing, t.kind, t.zone, t.status) for t in told] == [
        (task.id, task.thing, "deliver", "FAR", "cancelled")
    ]
    dispatcher.observe(robots.set(task.thing, last_command_id="by-name", last_result="done"))
    assert len(told) == 1


def test_an_update_from_before_the_acknowledgment_is_no_preemption(
    dispatcher: Dispatcher, robots: Robots
) -> None:
    robots.set("dragonfly", last_command_id="older", last_result="accepted")
    [task] = dispatcher.submit(Order(zone="FAR")).assigned
    assert task.thing == "dragonfly"
    dispatcher.observe(robots.states["dragonfly"])
    assert dispatcher.store.get(task.id).status == "assigned"  # type: ignore[union-attr]


def test_a_task_whose_command_cannot_be_sent_keeps_its_place(
    floor: Fleet, store: SqliteTaskStore, robots: Robots
) -> None:
    def unreachable(thing: str, command: Command) -> None:
        raise ConnectionError("broker down")

    dispatcher = Dispatcher(fleet=floor, store=store, candidates=robots, publish=unreachable)
    result = dispatcher.submit(Order(zone="FAR"))
    assert result.assigned == [] and result.positions == [1]


# --- two robots never take one task -----------------------------------------------------


def test_two_robots_freeing_at_once_take_different_tasks(
    floor: Fleet, store: SqliteTaskStore, robots: Robots, tmp_path: Path
) -> None:
    """Two dispatchers, each with its own connection to the one file, free a robot each at
    the same moment, many times over: every queued task is taken once, by one robot."""
    sent: list[tuple[str, Command]] = []
    lock = threading.Lock()

    def publish(thing: str, command: Command) -> None:
        with lock:
            sent.append((thing, command))

    first = Dispatcher(fleet=floor, store=store, candidates=robots, publish=publish)
    other_store = SqliteTaskStore.in_state_dir(tmp_path)
    second = Dispatcher(fleet=floor, store=other_store, candidates=robots, publish=publish)
    try:
        for round_ in range(20):
            for thing in robots.states:
                robots.set(thing, status="stuck")
            first.submit(Order(zone="FAR", count=3))
            for thing in ("ant", "bee"):
                robots.set(thing, status="idle")
            barrier = threading.Barrier(2)

            def free(dispatcher: Dispatcher, thing: str, barrier: threading.Barrier) -> None:
                barrier.wait()
                dispatcher.robot_freed(thing)

            threads = [
                threading.Thread(target=free, args=(first, "ant", barrier)),
                threading.Thread(target=free, args=(second, "bee", barrier)),
            ]
            for thread in threads:
                thread.start()
            for thread in threads:
                thread.join(timeout=10)
            active = store.active()
            assert sorted(task.thing or "" for task in active) == ["ant", "bee"], round_
            assert len({task.id for task in active}) == 2
            for task in active:
                store.finish(task.id, outcome="done")
            for task in store.pending():
                store.cancel(task.id)
        commanded = [command.id for _, command in sent]
        assert len(commanded) == len(set(commanded)) == 40
    finally:
        other_store.close()


def test_the_store_refuses_a_second_robot_and_a_second_task(store: SqliteTaskStore) -> None:
    one = msgspec_task("one", "2026-11-26T12:00:00.000000Z")
    two = msgspec_task("two", "2026-11-26T12:00:01.000000Z")
    store.add(one)
    store.add(two)
    assert store.assign("one", "ant", at="x") is not None
    assert store.assign("one", "bee", at="x") is None  # the task is taken
    assert store.assign("two", "ant", at="x") is None  # the robot is busy
    assert store.assign("two", "bee", at="x") is not None


def msgspec_task(task_id: str, created_at: str) -> Task:
    return Task(id=task_id, request="r", kind="navigate", zone="FAR", created_at=created_at)


# --- a dispatcher restarted mid-assignment ----------------------------------------------


def test_a_restarted_dispatcher_sends_again_what_no_robot_acknowledged(
    floor: Fleet, store: SqliteTaskStore, robots: Robots
) -> None:
    """The first dispatcher stored three assignments and died before publishing any: the
    next one sends each command again with the task's id, except where the robot already
    reports it (running, or finished: then the task is closed)."""
    for name in ("never-sent", "running", "finished"):
        store.add(msgspec_task(name, f"2026-11-26T12:00:0{len(name) % 10}.000000Z"))
    store.assign("never-sent", "ant", at="x")
    store.assign("running", "bee", at="x")
    store.assign("finished", "cricket", at="x")
    robots.set("bee", last_command_id="running", last_result="accepted", status="navigating")
    robots.set("cricket", last_command_id="finished", last_result="done")
    sent: list[tuple[str, Command]] = []
    restarted = Dispatcher(
        fleet=floor, store=store, candidates=robots, publish=lambda t, c: sent.append((t, c))
    )
    again = restarted.resume()
    assert [task.id for task in again] == ["never-sent"]
    assert [(thing, command.id, command.action) for thing, command in sent] == [
        ("ant", "never-sent", "navigate")
    ]
    assert store.get("finished").status == "done"  # type: ignore[union-attr]
    assert store.get("running").status == "assigned"  # type: ignore[union-attr]


def test_a_restart_with_the_broker_down_keeps_the_task_in_line(
    floor: Fleet, store: SqliteTaskStore, robots: Robots
) -> None:
    store.add(msgspec_task("stranded", "2026-11-26T12:00:00.000000Z"))
    store.assign("stranded", "ant", at="x")

    def unreachable(thing: str, command: Command) -> None:
        raise ConnectionError("broker down")

    Dispatcher(fleet=floor, store=store, candidates=robots, publish=unreachable).resume()
    assert [task.id for task in store.pending()] == ["stranded"]
