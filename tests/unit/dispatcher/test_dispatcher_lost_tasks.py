"""A queue that never loses a task, on AWS: the dispatcher function's schedule (the real
EventBridge event through `app.handle`) offers again an assigned task whose robot never
acknowledged it, and a task that cannot be carried out any more is told through the
announcer function, which says it to Alexa and on the operator station's topic.

Tasks in moto's DynamoDB, commands and announcements through moto's iot-data, candidates
from a fleet index on boto3's `iot` wire (the local data plane's); the announcer is the
real `announcer.app.announce` with its state in moto's DynamoDB, its secret in moto's
Secrets Manager and Alexa's endpoints stood in for on 127.0.0.1, reached through an
in-process stand-in of Lambda's asynchronous Invoke. What a person would observe: the
command on the robot's topic with the task's id, the sentence announced, the queue.
"""

from __future__ import annotations

import io
import json
import threading
import zipfile
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING, Any

import boto3
import pytest
from botocore.exceptions import ClientError
from moto import mock_aws
from moto.core import DEFAULT_ACCOUNT_ID
from moto.iotdata.models import iotdata_backends

from announcer import app as announcer_app
from announcer.aws import AnnouncementTopic, SkillCredentials, StateStore
from announcer.config import AnnouncerConfig
from announcer.proactive_events import ProactiveEvents
from dispatcher import app
from dispatcher.announcer_channel import AnnouncerChannel
from dispatcher.command_channel import CommandChannel
from dispatcher.errors import AnnounceError
from dispatcher.fleet_search import FleetSearch
from dispatcher.reoffer import MAX_REOFFERS, REOFFER_AFTER_S
from tests.support.dispatch_meter import REGION, load_event
from tests.unit.announcer.test_announcer import CLIENT_ID, CLIENT_SECRET, EVENTS_PATH, AlexaStandIn
from tests.unit.dispatcher.test_dispatcher_handler import Index
from vahr.announce.speech import Names
from vahr.dispatch import Dispatcher
from vahr.domain import load_fleet
from vahr.protocol import decode_command, topics
from vahr.protocol.announcements import decode_announcement
from vahr.protocol.lost_tasks import lost_task_from

if TYPE_CHECKING:
    from collections.abc import Iterator

    from dispatcher.task_table import TaskTable

START = datetime(2026, 11, 29, 1, 0, tzinfo=UTC)
TICK = load_event("eventbridge_schedule")


class Clock:
    """The dispatcher's clock, moved on by the test."""

    def __init__(self) -> None:
        self.now = START

    def __call__(self) -> datetime:
        return self.now

    def later(self, seconds: float) -> None:
        self.now += timedelta(seconds=seconds)


class InProcessAnnouncer:
    """Lambda's Invoke, running the announcer function's handler in this process."""

    def __init__(self, runtime: announcer_app.Runtime) -> None:
        self.runtime = runtime
        self.invocations: list[dict[str, Any]] = []

    def invoke(self, *, FunctionName: str, InvocationType: str, Payload: bytes) -> dict[str, Any]:  # noqa: N803
        assert (FunctionName, InvocationType) == ("vahr-announcer", "Event")
        event = json.loads(Payload)
        self.invocations.append(event)
        announcer_app.announce(event, self.runtime)
        return {"StatusCode": 202}


@pytest.fixture
def alexa() -> Iterator[AlexaStandIn]:
    server = AlexaStandIn()
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield server
    server.shutdown()
    server.server_close()
    thread.join(timeout=5)


@pytest.fixture
def announcer(dynamodb: Any, alexa: AlexaStandIn) -> InProcessAnnouncer:
    """The announcer function as the stack deploys it, inside the dispatcher's moto."""
    secrets = boto3.client("secretsmanager", region_name=REGION)
    secrets.create_secret(Name="vahr/skill-messaging", SecretString=json.dumps(
        {"clientId": CLIENT_ID, "clientSecret": CLIENT_SECRET}))  # fmt: skip
    dynamodb.create_table(
        TableName="vahr-announcer", BillingMode="PAY_PER_REQUEST",
        KeySchema=[{"AttributeName": "id", "KeyType": "HASH"}],
        AttributeDefinitions=[{"AttributeName": "id", "AttributeType": "S"}],
    )  # fmt: skip
    config = AnnouncerConfig.from_env({
        "VAHR_ANNOUNCER_SECRET": "vahr/skill-messaging", "VAHR_ANNOUNCER_TABLE": "vahr-announcer",
        "VAHR_PROACTIVE_EVENTS_URL": alexa.url + EVENTS_PATH,
        "VAHR_LWA_TOKEN_URL": alexa.url + "/auth/o2/token",
    })  # fmt: skip
    runtime = announcer_app.Runtime(
        config=config,
        names=Names.of(load_fleet()),
        store=StateStore(config.table),
        alexa=ProactiveEvents(
            token_url=config.token_url, events_url=config.events_url,
            credentials=SkillCredentials(config.secret), sleep=lambda s: None,
        ),
        topic=AnnouncementTopic(config.iot_data_endpoint),
    )  # fmt: skip
    return InProcessAnnouncer(runtime)


@pytest.fixture
def index() -> Iterator[Index]:
    served = Index()
    yield served
    served.server.stop()


@pytest.fixture
def wire(dynamodb: Any) -> list[tuple[str, bytes]]:
    """Everything published through moto's iot-data, in order (a live list)."""
    payloads: list[tuple[str, bytes]] = iotdata_backends[DEFAULT_ACCOUNT_ID][
        REGION
    ].published_payloads
    payloads.clear()
    return payloads


def commands(wire: list[tuple[str, bytes]], thing: str) -> list[tuple[str, str, str | None]]:
    """(id, action, zone) of each command on `thing`'s topic."""
    sent = [decode_command(payload) for topic, payload in wire if topic == topics.robot_cmd(thing)]
    return [(c.id, c.action, getattr(c.params, "zone", None)) for c in sent]


def spoken(wire: list[tuple[str, bytes]]) -> list[str]:
    """The sentences announced on the operator station's topic."""
    return [
        decode_announcement(payload).speech
        for topic, payload in wire
        if topic == topics.ASSISTANT_ANNOUNCEMENTS
    ]


class Function:
    """The dispatcher function as its runtime builds it, on a test clock."""

    def __init__(self, table: TaskTable, index: Index, announcer: InProcessAnnouncer) -> None:
        self.clock = Clock()
        self.index = index
        self.calls: list[str] = []
        iot = boto3.client("iot", endpoint_url=index.server.url)
        iot.meta.events.register(
            "provide-client-params.iot.SearchIndex",
            lambda params, **_: self.calls.append(params["queryString"]),
        )
        self.dispatcher = Dispatcher(
            fleet=load_fleet(),
            store=table,
            candidates=FleetSearch(client=iot, holding=table.holders),
            publish=CommandChannel(client=boto3.client("iot-data", region_name=REGION)),
            clock=self.clock,
        )
        self.tell = AnnouncerChannel("vahr-announcer", client=announcer)

    def submit(self, **order: Any) -> dict[str, Any]:
        answer = app.handle({"operation": "submit", "order": order}, self.dispatcher, None,
                            self.tell)  # fmt: skip
        assert answer["status"] == 200, answer
        return answer["body"]  # type: ignore[no-any-return]

    def tick(self, after_s: float = REOFFER_AFTER_S + 1) -> dict[str, Any]:
        self.clock.later(after_s)
        self.calls.clear()
        return app.handle(TICK, self.dispatcher, None, self.tell)

    def report(self, thing: str, **reported: Any) -> None:
        self.index.report(thing, **reported)


@pytest.fixture
def function(table: TaskTable, index: Index, announcer: InProcessAnnouncer) -> Function:
    # placebot1 idle in zone C, placebot2 stuck: only placebot1 may take a task.
    index.report("placebot1", status="idle", zone="C", pose={"x": 9.0, "y": 4.5})
    index.report("placebot2", status="stuck", zone="B")
    return Function(table, index, announcer)


def test_a_command_never_acknowledged_is_offered_again_with_its_id(
    function: Function, table: TaskTable, wire: list[tuple[str, bytes]]
) -> None:
    # Given a trip to zone A given to placebot1, whose command never reached it
    [task] = function.submit(zone="A")["assigned"]
    assert commands(wire, "placebot1") == [(task["id"], "navigate", "A")]
    # When the schedule comes within the grace, nothing is sent again
    assert function.tick(after_s=REOFFER_AFTER_S / 2)["offered_again"] == []
    # Then, the grace over, the same command (same id) is on placebot1's topic again
    tick = function.tick()
    assert tick["offered_again"] == [task["id"]] and tick["lost"] == []
    assert commands(wire, "placebot1") == [(task["id"], "navigate", "A")] * 2
    # And once placebot1 reports it has it, it is never sent again nor searched for
    function.report("placebot1", status="navigating", zone="C",
                    last_command={"id": task["id"], "action": "navigate", "result": "accepted"})  # fmt: skip
    assert function.tick()["acknowledged"] == [task["id"]]
    for _ in range(MAX_REOFFERS + 1):
        assert function.tick()["offered_again"] == [] and function.calls == []
    assert len(commands(wire, "placebot1")) == 2
    assert [t.id for t in table.active()] == [task["id"]]


def test_a_task_never_acknowledged_is_announced_once_offered_too_often(
    function: Function,
    table: TaskTable,
    wire: list[tuple[str, bytes]],
    announcer: InProcessAnnouncer,
    alexa: AlexaStandIn,
) -> None:
    # Given a delivery to zone C given to placebot1, which stays idle and never takes it
    [task] = function.submit(kind="deliver", zone="C")["assigned"]
    # When the schedule has sent it again as often as it may
    for _ in range(MAX_REOFFERS):
        assert function.tick()["offered_again"] == [task["id"]]
    tick = function.tick()
    # Then the task is lost, closed, and told: on Alexa and on the station's topic
    assert tick["lost"] == [task["id"]] and tick["offered_again"] == []
    assert len(commands(wire, "placebot1")) == 1 + MAX_REOFFERS
    ended = table.get(task["id"])
    assert ended is not None and (ended.status, ended.outcome) == ("cancelled", "cancelled")
    assert table.active() == []
    assert spoken(wire) == ["Placebot one is not doing its delivery to zone C, so it is cancelled."]
    [invocation] = announcer.invocations
    assert invocation["lost_task"] | {"at": None} == {
        "task": task["id"], "thing": "placebot1", "kind": "deliver", "zone": "C",
        "at": None, "why": "unacknowledged",
    }  # fmt: skip
    [sent] = alexa.events
    assert sent["event"]["payload"]["messageGroup"]["creator"]["name"] == "placebot one"
    # And a later tick tells it no more
    function.tick()
    assert len(spoken(wire)) == 1


def test_a_task_whose_robot_went_offline_is_announced_not_offered(
    function: Function, table: TaskTable, wire: list[tuple[str, bytes]]
) -> None:
    # Given a trip to zone D given to placebot1, which then went offline without it
    [task] = function.submit(zone="D")["assigned"]
    function.report("placebot1", status="idle", zone="C", connected=False)
    # When the schedule looks at it
    tick = function.tick()
    # Then it is not sent again into the void, but lost and announced
    assert tick["lost"] == [task["id"]] and tick["offered_again"] == []
    assert len(commands(wire, "placebot1")) == 1
    assert spoken(wire) == ["Placebot one went offline before it started its trip to zone D; it is cancelled."]  # fmt: skip
    assert table.active() == []


def test_a_task_finished_while_its_rule_event_was_lost_is_closed_and_the_next_given(
    function: Function, table: TaskTable, wire: list[tuple[str, bytes]]
) -> None:
    # Given placebot1 on a trip to zone A and a trip to zone B waiting behind it
    [first] = function.submit(zone="A")["assigned"]
    [second] = function.submit(zone="B")["queued"]
    # When placebot1 finished the first, but the rule's event never reached the function
    function.report("placebot1", status="idle", zone="A",
                    last_command={"id": first["id"], "action": "navigate", "result": "done"})  # fmt: skip
    tick = function.tick()
    # Then the schedule closes the first and sends placebot1 the second; nothing is lost
    assert tick["closed"] == [first["id"]] and tick["given"] == [second["id"]]
    done = table.get(first["id"])
    assert done is not None and done.outcome == "done"
    assert commands(wire, "placebot1")[-1] == (second["id"], "navigate", "B")
    assert spoken(wire) == []


def test_a_task_lost_to_a_command_by_name_is_announced(
    function: Function, table: TaskTable, wire: list[tuple[str, bytes]]
) -> None:
    # Given placebot1 took a delivery to zone C long ago
    function.clock.now = datetime.now(UTC) - timedelta(hours=1)
    [task] = function.submit(kind="deliver", zone="C")["assigned"]
    # When it reports free after finishing another command given by name
    other = load_event("shadow_documents_other_command_done")["current"]["state"]["reported"]
    app.handle({"thing": "placebot1", "reported": other}, function.dispatcher, None, function.tell)
    # Then the task ended preempted, and that was said
    ended = table.get(task["id"])
    assert ended is not None and ended.outcome == "preempted"
    assert spoken(wire) == ["Placebot one was given another command, so its delivery to zone C is cancelled."]  # fmt: skip


def test_without_an_announcer_a_lost_task_is_one_warning_in_the_log(
    function: Function, table: TaskTable, caplog: pytest.LogCaptureFixture
) -> None:
    [task] = function.submit(zone="D")["assigned"]
    function.report("placebot1", status="idle", zone="C", connected=False)
    function.tell = app._logged_only  # type: ignore[assignment]
    assert function.tick()["lost"] == [task["id"]]
    assert f"task {task['id']} lost (offline) is not announced" in caplog.text


def test_the_announcer_says_a_lost_task_from_its_real_shaped_invocation(
    announcer: InProcessAnnouncer, wire: list[tuple[str, bytes]]
) -> None:
    told = announcer_app.announce(load_event("lambda_lost_task"), announcer.runtime)
    assert len(told["told"]) == 1
    assert spoken(wire) == ["Placebot two went offline before it started its delivery to zone C; it is cancelled."]  # fmt: skip
    # And a malformed one is skipped with a warning, telling nothing
    bad = {"lost_task": {"task": "x", "why": "bored"}}
    assert announcer_app.announce(bad, announcer.runtime)["told"] == []


def test_the_announcer_says_a_robot_gone_to_charge_from_its_real_shaped_invocation(
    announcer: InProcessAnnouncer, wire: list[tuple[str, bytes]]
) -> None:
    told = announcer_app.announce(load_event("lambda_gone_to_charge"), announcer.runtime)
    assert len(told["told"]) == 1
    assert spoken(wire) == ["Placebot two is low on battery and is going to charge."]
    # And a malformed one is skipped with a warning, telling nothing
    bad = {"gone_to_charge": {"thing": "placebot2"}}
    assert announcer_app.announce(bad, announcer.runtime)["told"] == []


def test_the_announcer_is_invoked_asynchronously_and_a_refusal_is_one_line(
    aws_credentials: None,
) -> None:
    lost = lost_task_from(load_event("lambda_lost_task")["lost_task"])
    # Given the announcer function in moto's Lambda (which does not run its code)
    with mock_aws(config={"lambda": {"use_docker": False}}):
        role = boto3.client("iam").create_role(RoleName="announcer", AssumeRolePolicyDocument="{}")
        archive = io.BytesIO()
        with zipfile.ZipFile(archive, "w") as bundle:
            bundle.writestr("app.py", "def lambda_handler(event, context):\n    return None\n")
        client = boto3.client("lambda", region_name=REGION)
        client.create_function(
            FunctionName="vahr-announcer", Runtime="python3.12", Role=role["Role"]["Arn"],
            Handler="app.lambda_handler", Code={"ZipFile": archive.getvalue()},
        )  # fmt: skip
        requests: list[dict[str, Any]] = []
        client.meta.events.register(
            "provide-client-params.lambda.Invoke", lambda params, **_: requests.append(params)
        )
        # When a lost task is told, Lambda queues it (202) with the wire message as payload
        AnnouncerChannel("vahr-announcer", client=client)(lost)
        [request] = requests
        assert request["InvocationType"] == "Event"
        assert lost_task_from(json.loads(request["Payload"])["lost_task"]) == lost

    # And a refused invocation is one line naming the function and the task
    class Refusing:
        def invoke(self, **_: Any) -> None:
            raise ClientError(
                {"Error": {"Code": "AccessDeniedException", "Message": "denied"}}, "Invoke"
            )

    with pytest.raises(
        AnnounceError, match=r"^cannot tell the announcer vahr-announcer that task 7f3c\w+ is lost"
    ):
        AnnouncerChannel("vahr-announcer", client=Refusing())(lost)
