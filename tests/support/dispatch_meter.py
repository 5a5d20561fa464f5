"""What one dispatched task costs on AWS, counted on the real code: the dispatcher's handler
runs a submit and then the robot-freed event that closes the task, with its task table in
moto's DynamoDB, its commands through moto's iot-data and its candidates from a fleet index
on boto3's `iot` wire (the local data plane's, with AWS's pagination), and every AWS call
it makes is counted, with the DynamoDB request units each bills
(`infra.cost_estimate.dynamodb_units`).

Used by tests/unit/dispatcher/test_dispatcher_costs.py and bench/billable_operations.py.
Call it inside `moto.mock_aws()` with fake credentials set. Also the dispatcher tests'
helpers: `load_event` (tests/events/ by name) and `AtomicCalls`.
"""

from __future__ import annotations

import json
import threading
from collections import Counter
from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any

import boto3

from dispatcher import app
from dispatcher.announcer_channel import AnnouncerChannel
from dispatcher.command_channel import CommandChannel
from dispatcher.fleet_search import FleetSearch
from dispatcher.task_table import TaskTable
from infra.cost_estimate import dynamodb_units
from tests.support.dynamodb_tables import create_task_table
from vahr.dispatch import Dispatcher
from vahr.domain import load_fleet
from vahr.twin.dataplane import DataPlane, DataPlaneServer
from vahr.twin.meter import Meter
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore

REGION = "us-east-1"
TABLE = "vahr-tasks"
EVENTS = Path(__file__).resolve().parents[1] / "events"


def load_event(name: str) -> dict[str, Any]:
    """A real-shaped JSON document from tests/events/ by name."""
    loaded: dict[str, Any] = json.loads((EVENTS / f"{name}.json").read_text())
    return loaded


# moto applies a DynamoDB transaction to a copy of its tables and, when a condition fails,
# puts the copy back: a transaction failing in one thread can undo one that succeeded in
# another meanwhile. DynamoDB itself runs each request atomically, so the race tests make
# each moto call atomic too; what they race is what the dispatchers race on AWS, the
# reads and conditional writes in between.
_MOTO = threading.Lock()


class AtomicCalls:
    """A boto3 client whose calls run one at a time, as DynamoDB runs each request."""

    def __init__(self, client: Any) -> None:
        self._client = client

    def __getattr__(self, name: str) -> Any:
        attribute = getattr(self._client, name)
        if not callable(attribute):
            return attribute

        def call(*args: Any, **kwargs: Any) -> Any:
            with _MOTO:
                return attribute(*args, **kwargs)

        return call


@dataclass
class CallMeter:
    """AWS calls by operation, and the DynamoDB request units they bill."""

    calls: Counter[str] = field(default_factory=Counter)
    reads: float = 0.0
    writes: float = 0.0
    # (service, operation, parameters) of every call, in order.
    requests: list[tuple[str, str, dict[str, Any]]] = field(default_factory=list)

    def watch(self, client: Any) -> Any:
        client.meta.events.register("provide-client-params.*.*", self._remember)
        client.meta.events.register("after-call.*.*", self._count)
        return client

    def _remember(self, params: dict[str, Any], context: dict[str, Any], **_: Any) -> None:
        context["vahr_params"] = dict(params)

    def _count(self, parsed: dict[str, Any], model: Any, context: dict[str, Any], **_: Any) -> None:
        operation = model.name
        self.calls[operation] += 1
        service = model.service_model.service_name
        request = dict(context.get("vahr_params", {}))
        self.requests.append((service, operation, dict(request)))
        if service != "dynamodb":
            return
        if operation in ("GetItem", "Query"):
            request["_returned"] = parsed.get("Item") or parsed.get("Items") or []
        reads, writes = dynamodb_units(operation, request)
        self.reads += reads
        self.writes += writes


@dataclass(frozen=True)
class DispatchMeasure:
    """The calls and units of one task: its submit, the schedule's look at it once its
    robot had it (the tick's own reads of the open tasks and the closed zones, and the
    closures told, are the tick's whatever the tasks), and the event that closed it."""

    robots: int
    submit: CallMeter
    tick: CallMeter
    freed: CallMeter
    assigned_to: str


def _create_table(client: Any) -> None:
    client.create_table(
        TableName=TABLE,
        KeySchema=[
            {"AttributeName": "section", "KeyType": "HASH"},
            {"AttributeName": "id", "KeyType": "RANGE"},
        ],
        AttributeDefinitions=[
            {"AttributeName": "section", "AttributeType": "S"},
            {"AttributeName": "id", "AttributeType": "S"},
        ],
        BillingMode="PAY_PER_REQUEST",
    )


def measure_dispatch(robots: int) -> DispatchMeasure:
    """A delivery to zone C submitted to a fleet of `robots` idle, connected robots (the
    fleet file's two and `rover3`...), then the robot that took it reports it done."""
    store = ShadowStore(None)
    shadows = ShadowService(store, publish=lambda _topic, _payload: None)
    server = DataPlaneServer(DataPlane(shadows, publish=lambda *_: None, meter=Meter()), 0)
    fleet = load_fleet()
    names = [*fleet.robot_things, *(f"rover{n}" for n in range(3, robots + 1))][:robots]
    for n, thing in enumerate(names):
        robot = fleet.robots[n] if n < len(fleet.robots) else None
        pose = robot.start if robot is not None else None
        reported = {
            "status": "idle",
            "zone": "A",
            "connected": True,
            "pose": {"x": pose.x, "y": pose.y} if pose else {"x": 20.0 + n % 100, "y": 20.0},
        }
        store.update(thing, None, json.dumps({"state": {"reported": reported}}).encode())
    dynamodb = boto3.client("dynamodb", region_name=REGION)
    _create_table(dynamodb)
    now = [datetime.now(UTC)]
    with server:
        submit_meter, tick_meter, freed_meter = CallMeter(), CallMeter(), CallMeter()

        def dispatcher(meter: CallMeter) -> Dispatcher:
            # Built as the function's runtime builds it (dispatcher.app.runtime).
            table = TaskTable(
                TABLE, client=meter.watch(boto3.client("dynamodb", region_name=REGION))
            )
            core = Dispatcher(
                fleet=fleet,
                store=table,
                candidates=FleetSearch(
                    client=meter.watch(boto3.client("iot", endpoint_url=server.url)),
                    holding=table.holders,
                    usable=lambda robot: core.usable(robot),
                    out_of_service=table.out_of_service,
                ),
                publish=CommandChannel(
                    client=meter.watch(boto3.client("iot-data", region_name=REGION))
                ),
                clock=lambda: now[0],
            )
            return core

        answer = app.handle(
            {"operation": "submit", "order": {"kind": "deliver", "zone": "C"}},
            dispatcher(submit_meter),
        )
        [task] = answer["body"]["assigned"]
        # The robot took it; a minute later the schedule sees that, once.
        accepted = {
            "status": "navigating",
            "connected": True,
            "last_command": {"id": task["id"], "action": "deliver", "result": "accepted"},
        }
        store.update(task["thing"], None, json.dumps({"state": {"reported": accepted}}).encode())
        now[0] += timedelta(minutes=1)
        tick = app.handle(load_event("eventbridge_schedule"), dispatcher(tick_meter))
        assert tick["acknowledged"] == [task["id"]], tick
        done = {
            "status": "idle",
            "zone": "C",
            "connected": True,
            "last_command": {"id": task["id"], "action": "deliver", "result": "done"},
        }
        app.handle({"thing": task["thing"], "reported": done}, dispatcher(freed_meter))
    return DispatchMeasure(robots, submit_meter, tick_meter, freed_meter, task["thing"])


def measure_zone_change() -> CallMeter:
    """Zone B closed through the function's handler (on an empty table): the calls it makes,
    the closures' retained publish among them."""
    dynamodb = boto3.client("dynamodb", region_name=REGION)
    _create_table(dynamodb)
    meter = CallMeter()
    channel = CommandChannel(client=meter.watch(boto3.client("iot-data", region_name=REGION)))
    core = Dispatcher(
        fleet=load_fleet(),
        store=TaskTable(TABLE, client=meter.watch(boto3.client("dynamodb", region_name=REGION))),
        candidates=FleetSearch(client=boto3.client("iot", region_name=REGION)),
        publish=channel,
        publish_closures=channel.closures,
        clock=lambda: datetime.now(UTC),
    )
    answer = app.handle({"operation": "zone", "zone": "B", "closed": True}, core)
    assert answer["body"]["changed"] is True, answer
    return meter


# The announcer function the dispatcher tells of lost tasks (infra: its `function_name`).
ANNOUNCER = "vahr-announcer"


def measure_lost_task() -> CallMeter:
    """A trip to zone A given to placebot2, whose command never reaches it: the schedule
    sends it again, then placebot2 goes offline and the next tick tells the announcer the
    task is lost. Call it inside `mock_aws(config={"lambda": {"use_docker": False}})`."""
    store = ShadowStore(None)
    shadows = ShadowService(store, publish=lambda _topic, _payload: None)
    server = DataPlaneServer(DataPlane(shadows, publish=lambda *_: None, meter=Meter()), 0)

    def report(**reported: object) -> None:
        body = {"state": {"reported": {"status": "idle", "zone": "A", **reported}}}
        store.update("placebot2", None, json.dumps(body).encode())

    report(connected=True)
    create_task_table(boto3.client("dynamodb", region_name=REGION), TABLE)
    meter = CallMeter()
    now = [datetime.now(UTC)]
    tick = load_event("eventbridge_schedule")
    with server:
        table = TaskTable(TABLE, client=meter.watch(boto3.client("dynamodb", region_name=REGION)))
        core = Dispatcher(
            fleet=load_fleet(),
            store=table,
            candidates=FleetSearch(
                client=meter.watch(boto3.client("iot", endpoint_url=server.url)),
                holding=table.holders,
            ),
            publish=CommandChannel(
                client=meter.watch(boto3.client("iot-data", region_name=REGION))
            ),
            clock=lambda: now[0],
        )
        tell = AnnouncerChannel(
            ANNOUNCER, client=meter.watch(boto3.client("lambda", region_name=REGION))
        )
        answer = app.handle({"operation": "submit", "order": {"zone": "A"}}, core, None, tell)
        [task] = answer["body"]["assigned"]
        now[0] += timedelta(minutes=1)
        assert app.handle(tick, core, None, tell)["offered_again"] == [task["id"]]
        report(connected=False)
        now[0] += timedelta(minutes=1)
        assert app.handle(tick, core, None, tell)["lost"] == [task["id"]]
    return meter


def measure_service_and_charge(fleet_file: str | None = None) -> CallMeter:
    """Through the function's runtime on `fleet_file` (default: the bundled fleet), with
    every robot idle, full and connected: a task given, its robot taken out of service (the
    task goes to another), listed, put back, sent to charge (refused without a charger
    free), and a tick with a low robot idle. Call it inside `mock_aws()`."""
    fleet = load_fleet(fleet_file)
    store = ShadowStore(None)
    shadows = ShadowService(store, publish=lambda _topic, _payload: None)
    server = DataPlaneServer(DataPlane(shadows, publish=lambda *_: None, meter=Meter()), 0)

    def report(thing: str, percent: int) -> None:
        battery = {"percent": percent, "charging": False}
        body = {"state": {"reported": {"status": "idle", "zone": fleet.zones[0].id,
                                       "connected": True, "battery": battery}}}  # fmt: skip
        store.update(thing, None, json.dumps(body).encode())

    for thing in fleet.robot_things:
        report(thing, 100)
    create_task_table(boto3.client("dynamodb", region_name=REGION), TABLE)
    meter = CallMeter()
    with server:
        table = TaskTable(TABLE, client=meter.watch(boto3.client("dynamodb", region_name=REGION)))
        core = Dispatcher(
            fleet=fleet,
            store=table,
            candidates=FleetSearch(
                client=meter.watch(boto3.client("iot", endpoint_url=server.url)),
                holding=table.holders,
                out_of_service=table.out_of_service,
            ),
            publish=CommandChannel(
                client=meter.watch(boto3.client("iot-data", region_name=REGION))
            ),
        )
        first, second = fleet.robot_things[:2]
        answer = app.handle({"operation": "submit", "order": {"zone": fleet.zones[0].id}}, core)
        [task] = answer["body"]["assigned"]
        out = app.handle({"operation": "set_service", "thing": task["thing"], "in_service": False}, core)  # fmt: skip
        assert out["body"]["changed"] is True, out
        assert app.handle({"operation": "service"}, core)["body"]["out_of_service"]
        back = app.handle({"operation": "set_service", "thing": task["thing"], "in_service": True}, core)  # fmt: skip
        assert back["body"]["changed"] is True, back
        charged = app.handle({"operation": "charge", "thing": first}, core)
        assert charged["status"] == (200 if fleet.chargers else 400), charged
        report(second, 5)
        app.handle(load_event("eventbridge_schedule"), core)
    return meter
