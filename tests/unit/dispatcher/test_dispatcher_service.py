"""Robots out of service and charging through the dispatcher function, as the skill invokes
it: the function built from its environment (`app.runtime`) on three rovers and one charger,
tasks in moto's DynamoDB, commands through moto's iot-data, robots in a fleet index
answering boto3's `iot` client. What a user would observe: the answers and one-line
refusals the skill reads (the local host's shapes), the commands on the robots' topics,
the table afterwards, and the skill's own `LambdaTaskDesk` reading them."""

from __future__ import annotations

import json
import threading
from typing import TYPE_CHECKING, Any

import boto3
import msgspec
import pytest
from moto.core import DEFAULT_ACCOUNT_ID
from moto.iotdata.models import iotdata_backends

from dispatcher import app, fleet_search
from dispatcher.command_channel import CommandChannel
from dispatcher.fleet_search import FleetSearch
from dispatcher.task_table import TaskTable
from dispatcher.trail_table import TrailTable
from skill.audit_table import AuditTable
from skill.task_desk import LambdaTaskDesk, TaskRefused
from tests.support.dispatch_meter import REGION, AtomicCalls, load_event
from tests.support.dynamodb_tables import create_audit_table
from tests.support.fleets import THREE_ROVERS
from tests.unit.dispatcher.test_dispatcher_handler import Index
from tests.unit.skill.test_skill_task_desk import InProcessLambda
from vahr.dispatch import Dispatcher, Task
from vahr.protocol import topics
from vahr.protocol.lost_tasks import GoneToCharge, Tidings

if TYPE_CHECKING:
    from collections.abc import Iterator

# Everything published through moto's iot-data, in order (a live list).
Published = list[tuple[str, bytes]]

FULL = {"percent": 100, "charging": False}
LOW = {"percent": 10, "charging": False}
DOCK = "DOCK"
AUDIT_TABLE = "vahr-audit"


@pytest.fixture
def index() -> Iterator[Index]:
    served = Index()
    # Three idle rovers, full, far from the charger (DOCK at 9, 7).
    for n, x in ((1, 1.0), (2, 5.0), (3, 9.0)):
        served.report(f"rover{n}", status="idle", zone="A", pose={"x": x, "y": 1.0}, battery=FULL)
    yield served
    served.server.stop()


@pytest.fixture
def function(dynamodb: Any, index: Index, monkeypatch: pytest.MonkeyPatch) -> Iterator[Dispatcher]:
    """The function's runtime as a cold start builds it from the CDK stack's environment."""
    monkeypatch.setenv("VAHR_TASK_TABLE", "vahr-tasks")
    monkeypatch.setenv("VAHR_FLEET_FILE", str(THREE_ROVERS))
    monkeypatch.setenv("AWS_ENDPOINT_URL_IOT", index.server.url)
    app.runtime.cache_clear()
    yield app.runtime()
    app.runtime.cache_clear()


def call(dispatcher: Dispatcher, **event: Any) -> dict[str, Any]:
    return app.handle(event, dispatcher)


@pytest.fixture
def published(dynamodb: Any) -> Published:
    payloads: Published = iotdata_backends[DEFAULT_ACCOUNT_ID][REGION].published_payloads
    payloads.clear()
    return payloads


def commands(published: Published) -> list[tuple[str, str, dict[str, Any]]]:
    """(topic, action, params) of each command published to a robot, in order."""
    sent = [(t, json.loads(payload)) for t, payload in published if t != topics.FLEET_ZONES]
    return [(topic, cmd["action"], cmd.get("params", {})) for topic, cmd in sent]


def test_a_robot_out_of_service_gives_its_task_to_another_and_takes_none(
    function: Dispatcher, index: Index, table: TaskTable, published: Published
) -> None:
    # Given rover1 on a task
    [task] = call(function, operation="submit", order={"zone": "A"})["body"]["assigned"]
    assert task["thing"] == "rover1"
    published.clear()
    # When the skill takes rover1 out of service
    answer = call(function, operation="set_service", thing="rover1", in_service=False)
    # Then the answer is the local host's ServiceChange: its task went to another robot
    assert answer["status"] == 200
    change = answer["body"]
    assert (change["thing"], change["in_service"], change["changed"]) == ("rover1", False, True)
    [reassigned] = change["reassigned"]
    assert reassigned["id"] == task["id"] and reassigned["thing"] == "rover2"
    # And rover1 was told to stop, rover2 got the task's command
    assert [(t, action) for t, action, _ in commands(published)] == [
        (topics.robot_cmd("rover1"), "stop"),
        (topics.robot_cmd("rover2"), "navigate"),
    ]
    # And the function lists it out of service, with the tasks too
    assert call(function, operation="service") == {
        "status": 200,
        "body": {"out_of_service": ["rover1"]},
    }
    assert call(function, operation="tasks")["body"]["out_of_service"] == ["rover1"]
    # And asked again, nothing changes
    again = call(function, operation="set_service", thing="rover1", in_service=False)["body"]
    assert again["changed"] is False
    # And a task only rover1 may take waits for it, even when its rule event says idle
    published.clear()
    submitted = call(function, operation="submit", order={"zone": "B", "group": "ROVERS"})
    assert [t["thing"] for t in submitted["body"]["assigned"]] == ["rover3"]
    [mine] = [t for t in submitted["body"]["queued"] if t["robots"] == ["rover1"]]
    event = {"thing": "rover1", "reported": {"status": "idle", "zone": "A", "connected": True}}
    assert app.handle(event, function) == {"took": None}
    # When rover1 is back in service, it takes its task at once
    back = call(function, operation="set_service", thing="rover1", in_service=True)["body"]
    assert (back["in_service"], back["changed"]) == (True, True)
    assert [(t["id"], t["thing"]) for t in back["given"]] == [(mine["id"], "rover1")]
    assert table.out_of_service() == []


def test_a_robot_sent_to_charge_holds_the_one_charger(
    function: Dispatcher, table: TaskTable, published: Published
) -> None:
    # When the skill sends rover2 to charge
    answer = call(function, operation="charge", thing="rover2")
    # Then it holds the charger: a charge task, its command on rover2's topic
    assert answer["status"] == 200
    task = answer["body"]["task"]
    assert (task["kind"], task["zone"], task["thing"]) == ("charge", DOCK, "rover2")
    assert commands(published) == [(topics.robot_cmd("rover2"), "navigate", {"zone": DOCK})]
    assert table.chargers_held() == {DOCK: task["id"]}
    # And asked again, it is the same task
    assert call(function, operation="charge", thing="rover2")["body"]["task"]["id"] == task["id"]
    # And another robot is refused in one line: the charger is taken
    assert call(function, operation="charge", thing="rover1") == {
        "status": 400,
        "body": {
            "code": 400,
            "message": "every charger is taken or closed now",
            "error": "no_charger",
        },
    }
    assert len(commands(published)) == 1


def test_bad_requests_are_one_line_and_change_nothing(
    function: Dispatcher, table: TaskTable, published: Published
) -> None:
    refusals = [
        (
            {"operation": "charge", "thing": "rover9"},
            404,
            "rover9 is not a robot of the fleet",
            "unknown_robot",
        ),
        (
            {"operation": "set_service", "thing": "DOCK", "in_service": False},
            404,
            "DOCK is not a robot of the fleet",
            "unknown_robot",
        ),
        ({"operation": "charge"}, 400, "thing: is required but missing", None),
        (
            {"operation": "set_service", "thing": "rover1", "in_service": "no"},
            400,
            "in_service: expected bool, got str",
            None,
        ),
        (
            {"operation": "set_service", "thing": "rover1"},
            400,
            "in_service: is required but missing",
            None,
        ),
    ]
    call(function, operation="set_service", thing="rover3", in_service=False)
    for event, status, message, error in refusals:
        answer = call(function, **event)
        body = {"code": status, "message": message} | ({"error": error} if error else {})
        assert answer == {"status": status, "body": body}, event
    # A robot out of service cannot be sent to charge
    assert call(function, operation="charge", thing="rover3")["body"] == {
        "code": 400,
        "message": "rover3 is out of service",
        "error": "out_of_service",
    }
    assert table.out_of_service() == ["rover3"]
    assert table.active() == table.pending() == []
    assert table.chargers_held() == {}
    assert [action for _, action, _ in commands(published)] == []


def test_a_first_page_of_low_robots_is_read_past(
    function: Dispatcher, index: Index, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given pages of two robots, the first two rovers low and charging (so not sent to
    # charge), only rover3 able to take a task
    monkeypatch.setattr(fleet_search, "PAGE_SIZE", 2)
    for thing in ("rover1", "rover2"):
        index.report(thing, battery={"percent": 10, "charging": True})
    # When the skill sends a robot
    answer = call(function, operation="submit", order={"zone": "A"})
    # Then rover3, on the second page, goes: the search read past the low ones
    assert [t["thing"] for t in answer["body"]["assigned"]] == ["rover3"]


def test_the_schedule_sends_an_idle_low_robot_to_charge(
    function: Dispatcher, index: Index, table: TaskTable, published: Published, dynamodb: Any
) -> None:
    # Given rover1 ran low standing idle (no rule event: its status never changed)
    index.report("rover1", battery=LOW)
    tick = load_event("eventbridge_schedule")
    create_audit_table(dynamodb, AUDIT_TABLE)
    # When the schedule ticks
    told: list[Tidings] = []
    answer = app.handle(tick, function, TrailTable(AUDIT_TABLE, dynamodb), told.append)
    # Then rover1 holds the charger and is on its way
    [task] = table.active()
    assert (task.kind, task.zone, task.thing) == ("charge", DOCK, "rover1")
    assert answer["charging"] == [task.id]
    assert commands(published) == [(topics.robot_cmd("rover1"), "navigate", {"zone": DOCK})]
    # And the announcer is told, as the local stack tells its announcer
    assert [(t.thing, t.zone) for t in told if isinstance(t, GoneToCharge)] == [("rover1", DOCK)]
    # And the trail records that the dispatcher sent it
    [record] = AuditTable(AUDIT_TABLE, dynamodb).records()
    assert (record.who, record.robots, record.commands) == ("dispatcher", ["rover1"], [task.id])
    # And the next tick sends nothing more (rover2 low too: the one charger is taken)
    index.report("rover2", battery=LOW)
    assert app.handle(tick, function)["charging"] == []
    assert len(commands(published)) == 1


def test_a_robot_freed_low_goes_to_charge_and_the_announcer_is_told(
    function: Dispatcher, index: Index, table: TaskTable, published: Published
) -> None:
    # Given rover2 low, when its update says it is idle (the rule selects it)
    index.report("rover2", battery=LOW)
    reported = {"status": "idle", "zone": "A", "pose": {"x": 5.0, "y": 1.0}, "battery": LOW,
                "connected": True}  # fmt: skip
    told: list[Tidings] = []
    answer = app.handle({"thing": "rover2", "reported": reported}, function, None, told.append)
    # Then it takes the charger, and the announcer is told it went to charge
    [task] = table.active()
    assert (answer["took"], task.kind, task.thing) == (task.id, "charge", "rover2")
    assert [(t.thing, t.zone) for t in told if isinstance(t, GoneToCharge)] == [("rover2", DOCK)]


def test_two_invocations_racing_for_one_charger_give_it_to_one_robot(
    function: Dispatcher, index: Index, table: TaskTable, published: Published
) -> None:
    """Two function instances, two robots sent to charge at once, one charger."""
    start = threading.Barrier(2)
    answers: dict[str, Any] = {}

    def charge(thing: str) -> None:
        # An instance of its own, as Lambda's, on a client whose calls are atomic
        store = TaskTable(
            "vahr-tasks", client=AtomicCalls(boto3.client("dynamodb", region_name=REGION))
        )
        dispatcher = Dispatcher(
            fleet=function.fleet,
            store=store,
            candidates=FleetSearch(
                client=boto3.client("iot", endpoint_url=index.server.url),
                holding=store.holders,
                out_of_service=store.out_of_service,
            ),
            publish=CommandChannel(client=boto3.client("iot-data", region_name=REGION)),
        )
        start.wait(timeout=60)
        try:
            answers[thing] = app.handle({"operation": "charge", "thing": thing}, dispatcher)
        except Exception as err:  # noqa: BLE001 - shown by the assertion below
            answers[thing] = err

    threads = [threading.Thread(target=charge, args=(t,)) for t in ("rover1", "rover2")]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=30)
    # Then one robot holds the charger and the other heard why not
    statuses = sorted(answer["status"] for answer in answers.values())
    assert statuses == [200, 400], answers
    [holder] = [thing for thing, answer in answers.items() if answer["status"] == 200]
    [refused] = [answer["body"] for answer in answers.values() if answer["status"] == 400]
    assert refused["error"] == "no_charger"
    [task] = table.active()
    assert (task.kind, task.thing) == ("charge", holder)
    assert table.chargers_held() == {DOCK: task.id}
    assert [topic for topic, _, _ in commands(published)] == [topics.robot_cmd(holder)]


def test_the_table_never_gives_one_charger_to_two_robots(dynamodb: Any) -> None:
    """Two charge tasks for one charger both queued, assigned by two tables at once: the
    charger's hold, a conditional write, lets one through."""
    tables = [
        TaskTable("vahr-tasks", client=AtomicCalls(boto3.client("dynamodb", region_name=REGION)))
        for _ in range(2)
    ]
    tasks = [
        Task(
            id=f"charge-{n}",
            request=f"r{n}",
            kind="charge",
            zone=DOCK,
            robots=[f"rover{n}"],
            created_at="2026-11-29T03:00:00.000000Z",
        )
        for n in (1, 2)
    ]
    for task in tasks:
        tables[0].add(task)
    start = threading.Barrier(2)
    taken: list[Task | None] = [None, None]

    def assign(n: int) -> None:
        start.wait(timeout=60)
        taken[n] = tables[n].assign(tasks[n].id, f"rover{n + 1}", at="2026-11-29T03:00:01Z")

    threads = [threading.Thread(target=assign, args=(n,)) for n in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=30)
    [winner] = [task for task in taken if task is not None]
    assert tables[0].chargers_held() == {DOCK: winner.id}
    [loser] = [task for task in tasks if task.id != winner.id]
    # Once the winner is done charging, the charger is free for the other
    assert tables[0].finish(winner.id, outcome="done") is not None
    assert tables[0].chargers_held() == {}
    assert tables[1].assign(loser.id, loser.robots[0], at="2026-11-29T03:10:00Z") is not None
    assert tables[0].chargers_held() == {DOCK: loser.id}
    # And released (its command could not be sent), it lets the charger go
    assert tables[0].release(loser.id) is not None
    assert tables[0].chargers_held() == {}


def test_the_skills_desk_reads_service_and_charge_from_the_function(
    function: Dispatcher, published: Published
) -> None:
    desk = LambdaTaskDesk("vahr-dispatcher", client=InProcessLambda(function))
    assert desk.out_of_service() == []
    change = desk.set_service("rover2", in_service=False)
    assert (change.thing, change.in_service, change.changed) == ("rover2", False, True)
    assert desk.out_of_service() == ["rover2"]
    task = desk.charge("rover1")
    assert (task.kind, task.zone, task.thing) == ("charge", DOCK, "rover1")
    with pytest.raises(TaskRefused) as refused:
        desk.charge("rover3")
    assert (refused.value.status, refused.value.error) == (400, "no_charger")
    assert str(refused.value) == "every charger is taken or closed now"
    with pytest.raises(TaskRefused) as unknown:
        desk.set_service("rover9", in_service=False)
    assert (unknown.value.status, unknown.value.error) == (404, "unknown_robot")
    back = desk.set_service("rover2", in_service=True)
    assert msgspec.to_builtins(back)["changed"] is True
    assert desk.out_of_service() == []
