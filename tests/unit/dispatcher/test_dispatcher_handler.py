"""The dispatcher's handler as the skill and the topic rule invoke it: tasks in moto's
DynamoDB, commands through moto's iot-data, candidates from a fleet index answering boto3's
`iot` client (the local data plane's, the same wire as AWS's SearchIndex). What a user
would observe: which robot's command topic got which command, the answer the skill reads,
the queue, and one-line errors that change nothing."""

from __future__ import annotations

import json
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING, Any

import boto3
import msgspec
import pytest
from moto.core import DEFAULT_ACCOUNT_ID
from moto.iotdata.models import iotdata_backends

from dispatcher import app
from dispatcher.command_channel import CommandChannel
from dispatcher.config import DispatcherConfig
from dispatcher.errors import ConfigError, DispatcherError
from dispatcher.fleet_search import FleetSearch
from dispatcher.task_table import TaskTable
from dispatcher.trail_table import TrailTable
from skill.audit_table import AuditTable
from tests.support.dispatch_meter import REGION, AtomicCalls, load_event
from tests.support.dynamodb_tables import create_audit_table
from vahr.dispatch import Dispatcher, Task, timestamp
from vahr.domain import load_fleet
from vahr.protocol import topics
from vahr.twin.dataplane import DataPlane, DataPlaneServer
from vahr.twin.meter import Meter
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore

if TYPE_CHECKING:
    from collections.abc import Iterator


LONG_AGO = datetime(2026, 11, 26, 22, 0, tzinfo=UTC)
OPERATIONS = "submit, tasks, pending, cancel, zones, zone, service, set_service, charge"
AUDIT_TABLE = "vahr-audit"


class Index:
    """A fleet index served over HTTP as boto3's `iot` client expects it."""

    def __init__(self) -> None:
        self.store = ShadowStore(None)
        shadows = ShadowService(self.store, publish=lambda _topic, _payload: None)
        self.server = DataPlaneServer(
            DataPlane(shadows, publish=lambda *_: None, meter=Meter()), 0
        ).start()

    def report(self, thing: str, **reported: Any) -> None:
        body = {"state": {"reported": {"connected": True, **reported}}}
        self.store.update(thing, None, json.dumps(body).encode())


@pytest.fixture
def index() -> Iterator[Index]:
    served = Index()
    yield served
    served.server.stop()


@pytest.fixture
def published(dynamodb: Any) -> list[tuple[str, dict[str, Any]]]:
    """Every command published through moto's iot-data, decoded, in order (a live view)."""
    backend = iotdata_backends[DEFAULT_ACCOUNT_ID][REGION]
    backend.published_payloads.clear()

    class View(list[tuple[str, dict[str, Any]]]):
        def __iter__(self):  # type: ignore[no-untyped-def]
            return iter([(t, json.loads(p)) for t, p in backend.published_payloads])

        def __len__(self) -> int:
            return len(backend.published_payloads)

    return View()


def make_dispatcher(
    table: TaskTable, index: Index, *, clock: Any = lambda: datetime.now(UTC)
) -> Dispatcher:
    return Dispatcher(
        fleet=load_fleet(),
        store=table,
        candidates=FleetSearch(client=boto3.client("iot", endpoint_url=index.server.url)),
        publish=CommandChannel(client=boto3.client("iot-data", region_name=REGION)),
        clock=clock,
    )


@pytest.fixture
def dispatcher(table: TaskTable, index: Index) -> Dispatcher:
    # placebot1 by zone C's door, placebot2 at the loading zone: both idle.
    index.report("placebot1", status="idle", zone="C", pose={"x": 9.0, "y": 4.5})
    index.report("placebot2", status="idle", zone="LOADING", pose={"x": 1.5, "y": 4.0})
    return make_dispatcher(table, index)


def submit(dispatcher: Dispatcher, **order: Any) -> dict[str, Any]:
    return app.handle({"operation": "submit", "order": order}, dispatcher)


def test_a_delivery_goes_to_the_nearest_free_robot_and_the_skill_hears_which(
    dispatcher: Dispatcher, published: list[tuple[str, dict[str, Any]]]
) -> None:
    # When the skill submits "deliver a package to zone C"
    answer = submit(dispatcher, kind="deliver", zone="C")
    # Then placebot2, already at the loading zone, takes it (pickup there, then C)
    assert answer["status"] == 200
    [task] = answer["body"]["assigned"]
    assert (task["thing"], task["kind"], task["zone"], task["pickup"]) == (
        "placebot2", "deliver", "C", "LOADING",
    )  # fmt: skip
    assert answer["body"]["queued"] == []
    # And the command went to placebot2's topic only, carrying the task's id
    [(topic, command)] = list(published)
    assert topic == topics.robot_cmd("placebot2")
    assert (command["id"], command["action"], command["params"]) == (
        task["id"], "deliver", {"zone": "C"},
    )  # fmt: skip


def test_with_every_robot_taken_the_task_is_queued_and_its_place_said(
    dispatcher: Dispatcher, published: list[tuple[str, dict[str, Any]]]
) -> None:
    submit(dispatcher, zone="A", count=2)
    answer = submit(dispatcher, kind="deliver", zone="B")
    assert answer["status"] == 200
    assert answer["body"]["assigned"] == []
    [queued] = answer["body"]["queued"]
    # (a queued task's status is the model's default, which the JSON leaves out)
    assert (queued.get("status", "queued"), queued["zone"], queued.get("thing")) == (
        "queued", "B", None,
    )  # fmt: skip
    assert answer["body"]["positions"] == [1]
    assert len(published) == 2  # nothing more was sent
    listed = app.handle({"operation": "pending"}, dispatcher)
    assert [t["id"] for t in listed["body"]["tasks"]] == [queued["id"]]
    everything = app.handle({"operation": "tasks"}, dispatcher)
    statuses = [t.get("status", "queued") for t in everything["body"]["tasks"]]
    assert statuses == ["assigned", "assigned", "queued"]


def test_a_robot_that_finishes_its_task_takes_the_next_in_line(
    table: TaskTable, index: Index, published: list[tuple[str, dict[str, Any]]], dynamodb: Any
) -> None:
    # Given placebot1 alone, holding task T (the fixture's id), and a delivery queued
    rule_event = load_event("iot_rule_robot_freed")
    task_id = rule_event["reported"]["last_command"]["id"]
    index.report("placebot1", status="navigating", zone="B", pose={"x": 9.0, "y": 5.0})
    dispatcher = make_dispatcher(table, index)
    created = timestamp(datetime.now(UTC) - timedelta(minutes=1))
    table.add(Task(id=task_id, request="r", kind="navigate", zone="C", created_at=created))
    assert table.assign(task_id, "placebot1", at=timestamp(datetime.now(UTC))) is not None
    queued = submit(dispatcher, kind="deliver", zone="D")["body"]["queued"][0]
    # When the rule reports placebot1 idle with T done
    index.report("placebot1", **rule_event["reported"])
    trail = audit_trail(dynamodb)
    answer = app.handle(rule_event, dispatcher, trail)
    # Then T is done and placebot1 took the delivery
    assert answer == {"took": queued["id"]}
    done = table.get(task_id)
    assert done is not None and (done.status, done.outcome) == ("done", "done")
    topic, command = list(published)[-1]
    assert (topic, command["id"], command["action"]) == (
        topics.robot_cmd("placebot1"), queued["id"], "deliver",
    )  # fmt: skip
    assert app.handle({"operation": "pending"}, dispatcher)["body"]["tasks"] == []
    # And the audit trail records the dispatcher's own act: the task, the robot, the channel
    [record] = AuditTable(AUDIT_TABLE, dynamodb).records()
    assert (record.who, record.channel, record.outcome) == ("dispatcher", "dispatcher", "sent")
    assert (record.robots, record.commands) == (["placebot1"], [queued["id"]])


def audit_trail(dynamodb: Any) -> TrailTable:
    """The audit table the stack makes (keys as infra/constructs/people_tables.py), in moto."""
    create_audit_table(dynamodb, AUDIT_TABLE)
    return TrailTable(AUDIT_TABLE, dynamodb)


def test_a_task_lost_to_a_command_by_name_is_closed_after_the_grace(
    table: TaskTable, index: Index, published: list[tuple[str, dict[str, Any]]]
) -> None:
    # Given placebot1 was given a task long ago, and a delivery waits
    index.report("placebot1", status="idle", zone="B", pose={"x": 9.0, "y": 5.0})
    held = submit(make_dispatcher(table, index, clock=lambda: LONG_AGO), zone="C")
    held_id = held["body"]["assigned"][0]["id"]
    dispatcher = make_dispatcher(table, index)
    queued = submit(dispatcher, zone="D")["body"]["queued"][0]
    # When it reports free after finishing another command (given by name)
    other = load_event("shadow_documents_other_command_done")["current"]["state"]["reported"]
    answer = app.handle({"thing": "placebot1", "reported": other}, dispatcher)
    # Then its task ended preempted and it took the next one
    ended = table.get(held_id)
    assert ended is not None and ended.outcome == "preempted"
    assert answer == {"took": queued["id"]}


def test_a_robot_free_on_another_command_just_after_assignment_keeps_its_task(
    dispatcher: Dispatcher, table: TaskTable, published: list[tuple[str, dict[str, Any]]]
) -> None:
    """Its task's command may still be on the way: nothing is changed."""
    held = submit(dispatcher, zone="C", count=2)["body"]["assigned"]
    other = load_event("shadow_documents_other_command_done")["current"]["state"]["reported"]
    answer = app.handle({"thing": "placebot1", "reported": other}, dispatcher)
    assert answer == {"took": None}
    assert {t.thing for t in table.active()} == {"placebot1", "placebot2"}
    assert len(published) == len(held)


def test_cancel_stops_the_robot_and_frees_it(
    dispatcher: Dispatcher, table: TaskTable, published: list[tuple[str, dict[str, Any]]]
) -> None:
    task = submit(dispatcher, zone="A")["body"]["assigned"][0]
    answer = app.handle({"operation": "cancel", "task_id": task["id"]}, dispatcher)
    assert answer["status"] == 200 and answer["body"]["task"]["id"] == task["id"]
    topic, command = list(published)[-1]
    assert (topic, command["action"]) == (topics.robot_cmd(task["thing"]), "stop")
    assert table.active() == []


@pytest.mark.parametrize(
    ("request_body", "status", "message", "error"),
    [
        ({"operation": "submit", "order": {"zone": "Z"}}, 400,
         "there is no zone 'Z'; zones are LOADING, A, B, C, D", "unknown_zone"),
        ({"operation": "submit", "order": {"zone": "A", "count": 5}}, 400,
         "the fleet has 2 robots; 5 cannot go", "too_many"),
        ({"operation": "submit", "order": {"zone": "A", "colour": "red"}}, 400,
         "order.colour: is not a known field", None),
        ({"operation": "submit"}, 400, "order: is required but missing", None),
        ({"operation": "cancel", "task_id": "nope"}, 404, "no open task 'nope'", None),
        ({"operation": "launch"}, 400, f"operation: 'launch' is not one of {OPERATIONS}", None),
        ({}, 400, f"operation: 'None' is not one of {OPERATIONS}", None),
        ({"operation": "zone", "zone": "Z", "closed": True}, 400,
         "there is no zone 'Z'; zones are LOADING, A, B, C, D", "unknown_zone"),
    ],
)  # fmt: skip
def test_a_request_that_cannot_be_done_is_one_line_and_changes_nothing(
    dispatcher: Dispatcher,
    table: TaskTable,
    published: list[tuple[str, dict[str, Any]]],
    request_body: dict[str, Any],
    status: int,
    message: str,
    error: str | None,
) -> None:
    answer = app.handle(request_body, dispatcher)
    # An order the dispatcher refused says why by its code, which the skill decides by.
    refusal = {"code": status, "message": message} | ({"error": error} if error else {})
    assert answer == {"status": status, "body": refusal}
    assert table.pending() == [] and table.active() == [] and len(published) == 0
    assert table.closed_zones() == []


def test_a_malformed_rule_event_or_a_stranger_is_dropped(
    dispatcher: Dispatcher, table: TaskTable
) -> None:
    assert app.handle({"thing": 7, "reported": "idle"}, dispatcher) == {"took": None}
    idle = {"status": "idle", "connected": True}
    assert app.handle({"thing": "intruder", "reported": idle}, dispatcher) == {"took": None}
    assert table.pending() == [] and table.active() == []


def test_the_configuration_is_read_once_and_refuses_a_missing_table() -> None:
    with pytest.raises(ConfigError, match=r"^VAHR_TASK_TABLE: not set \(the CDK stack sets it\)$"):
        DispatcherConfig.from_env({})
    config = DispatcherConfig.from_env(
        {"VAHR_TASK_TABLE": "t", "VAHR_IOT_DATA_ENDPOINT": "abc-ats.iot.us-east-1.amazonaws.com"}
    )
    assert config.iot_data_endpoint == "https://abc-ats.iot.us-east-1.amazonaws.com"
    assert (config.index_name, config.closed_task_days) == ("AWS_Things", 30)
    with pytest.raises(ConfigError, match=r"^VAHR_CLOSED_TASK_DAYS: 0 must be 1 to 365$"):
        DispatcherConfig.from_env({"VAHR_TASK_TABLE": "t", "VAHR_CLOSED_TASK_DAYS": "0"})


def test_the_answer_is_plain_json(dispatcher: Dispatcher) -> None:
    answer = submit(dispatcher, zone="B")
    assert msgspec.json.decode(msgspec.json.encode(answer)) == answer


def test_the_lambda_entry_point_builds_its_adapters_from_the_environment(
    dynamodb: Any,
    index: Index,
    published: list[tuple[str, dict[str, Any]]],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Given the environment the CDK stack sets (the index reached through boto3's own
    # variable for the IoT control plane)
    index.report("placebot2", status="idle", zone="B", pose={"x": 9.0, "y": 5.0})
    monkeypatch.setenv("VAHR_TASK_TABLE", "vahr-tasks")
    monkeypatch.setenv("AWS_ENDPOINT_URL_IOT", index.server.url)
    app.runtime.cache_clear()
    try:
        # When the skill invokes the function
        answer = app.lambda_handler({"operation": "submit", "order": {"zone": "A"}}, None)
        # Then the task is placebot2's and its command is on placebot2's topic
        [task] = answer["body"]["assigned"]
        assert task["thing"] == "placebot2"
        assert [topic for topic, _ in published] == [topics.robot_cmd("placebot2")]
        # And a missing table is a failed invocation with one line, not an answer
        monkeypatch.setenv("VAHR_TASK_TABLE", "no-such-table")
        app.runtime.cache_clear()
        with pytest.raises(
            DispatcherError, match=r"^cannot read the closed zones: ResourceNotFound"
        ):
            app.lambda_handler({"operation": "submit", "order": {"zone": "A"}}, None)
    finally:
        app.runtime.cache_clear()


def test_two_robots_freed_at_once_take_one_queued_task_once(
    table: TaskTable, index: Index, published: list[tuple[str, dict[str, Any]]]
) -> None:
    """Two rule events, two function instances, one queued task: one robot takes it."""
    import threading

    # Given both robots reported busy-with-errors (no candidate), and one task queued
    index.report("placebot1", status="stuck", zone="B")
    index.report("placebot2", status="stuck", zone="C")
    queued = submit(make_dispatcher(table, index), zone="D")["body"]["queued"][0]
    # When both become idle and their events are handled at the same moment
    for thing in ("placebot1", "placebot2"):
        index.report(thing, status="idle", zone="B")
    start = threading.Barrier(2)
    took: dict[str, Any] = {}

    def freed(thing: str) -> None:
        # An instance of its own, as Lambda's, on a client whose calls are atomic
        # (conftest.AtomicCalls: DynamoDB's are, moto's are not)
        store = TaskTable(
            "vahr-tasks", client=AtomicCalls(boto3.client("dynamodb", region_name=REGION))
        )
        dispatcher = make_dispatcher(store, index)
        event = {"thing": thing, "reported": {"status": "idle", "zone": "B", "connected": True}}
        start.wait(timeout=60)
        try:
            took[thing] = app.handle(event, dispatcher)["took"]
        except Exception as err:  # noqa: BLE001 - shown by the assertion below
            took[thing] = err

    threads = [threading.Thread(target=freed, args=(t,)) for t in ("placebot1", "placebot2")]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=20)
    # Then exactly one of them took it, and exactly one command went out
    assert not [err for err in took.values() if isinstance(err, Exception)], took
    assert sorted(took.values(), key=lambda taken: taken is None) == [queued["id"], None]
    [holder] = [thing for thing, task in took.items() if task is not None]
    assert [(t.id, t.thing) for t in table.active()] == [(queued["id"], holder)]
    assert [topic for topic, _ in published] == [topics.robot_cmd(holder)]


def test_the_schedule_gives_a_queued_task_to_a_robot_whose_event_was_lost(
    table: TaskTable, index: Index, published: list[tuple[str, dict[str, Any]]]
) -> None:
    # Given a task queued while the only robot was stuck
    index.report("placebot1", status="stuck", zone="B")
    dispatcher = make_dispatcher(table, index)
    queued = submit(dispatcher, zone="D")["body"]["queued"][0]
    tick = load_event("eventbridge_schedule")
    assert app.handle(tick, dispatcher)["given"] == []  # still stuck: nothing to give
    # When the robot is idle again but its rule event never reached the function
    index.report("placebot1", status="idle", zone="B")
    # Then the next tick gives it the task
    assert app.handle(tick, dispatcher)["given"] == [queued["id"]]
    assert [topic for topic, _ in published] == [topics.robot_cmd("placebot1")]
