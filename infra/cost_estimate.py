"""The monthly AWS cost of a VAHR lab, computed from billable operation counts.

    python -m infra.cost_estimate [--lex] [--skill]
    python -m infra.cost_estimate --fleet

Every count comes from what the code does on the wire (docs/protocol.md's loop, the robot's
events and shadow updates, the skill's publish-then-poll), multiplied out for the usage
below; every price is a us-east-1 list price. docs/deploy.md shows this script's output,
and a test keeps the two in step.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Sequence

PRICES_AS_OF = "2026-11-22"
# Where the prices come from (list prices, us-east-1, read on PRICES_AS_OF):
# https://aws.amazon.com/iot-core/pricing/ (connectivity, messaging, Device Shadow and
# registry, rules engine; metering in 5 KB message and 1 KB shadow units),
# https://aws.amazon.com/lambda/pricing/, https://aws.amazon.com/lex/pricing/,
# https://aws.amazon.com/cloudwatch/pricing/, https://aws.amazon.com/secrets-manager/pricing/,
# https://aws.amazon.com/iot-device-management/pricing/ (fleet indexing: index updates
# metered in 1 KB increments, search queries).


@dataclass(frozen=True)
class Prices:
    """us-east-1 list prices, USD."""

    connection_minute: float = 0.08 / 1e6  # AWS IoT Core connectivity
    message: float = 1.00 / 1e6  # AWS IoT Core messaging, per 5 KB message (first billion)
    shadow_operation: float = 1.25 / 1e6  # Device Shadow and registry, per 1 KB operation
    rule_triggered: float = 0.15 / 1e6
    rule_action: float = 0.15 / 1e6
    lambda_request: float = 0.20 / 1e6
    lambda_gb_second: float = 0.0000166667  # x86_64 (arm64: 0.0000133334)
    lex_text_request: float = 0.00075  # Lex V2 RecognizeText
    log_ingestion_gb: float = 0.50  # CloudWatch Logs
    secret_month: float = 0.40  # Secrets Manager, the Login-with-Amazon secret
    secret_api_call: float = 0.05 / 10_000  # Secrets Manager GetSecretValue
    # DynamoDB on demand (https://aws.amazon.com/dynamodb/pricing/on-demand/).
    dynamodb_read: float = 0.125 / 1e6  # per read request unit (4 KB, strongly consistent)
    dynamodb_write: float = 0.625 / 1e6  # per write request unit (1 KB)
    # AWS IoT Device Management fleet indexing: an index update per 1 KB of a registry or
    # shadow change, a query per SearchIndex call (each page) or aggregation call.
    fleet_index_update: float = 2.25 / 1e6
    fleet_index_query: float = 0.05 / 10_000


@dataclass(frozen=True)
class LabUsage:
    """The paper's usage: two robots, a study of voice and keyboard sessions in one month."""

    robots: int = 2
    lab_days: int = 22
    robot_hours_per_day: float = 8.0
    # 20 participants x 2 trials with each method, plus 20 rehearsal and demo runs by voice.
    voice_sessions: int = 60
    keyboard_sessions: int = 40
    session_minutes: float = 15.0
    # Per session: task I two deliveries, task II one, task III two (docs/experiment.md).
    deliveries_per_session: int = 5
    # Voice: four commands, the robot's weather question, three status questions, and one
    # in four utterances repeated (misheard, or asked again).
    skill_requests_per_voice_session: float = 10.0
    # The robot asks the weather once per session, sometimes twice.
    weather_questions_per_session: float = 1.25
    # A delivery drives ~16 m at 0.5 m/s in two legs. At robot-agent's default progress
    # rate (at most one report every 5 s and per quarter of the way) it sends about ten
    # events (accepted, a few progress reports, arrived x2, loaded, delivered, done) and
    # about nine shadow updates as its state changes (bench/billable_operations.py).
    events_per_delivery: int = 10
    shadow_updates_per_delivery: int = 9
    # Who receives a robot's event: its peer and the experiment recorder.
    event_subscribers: int = 2
    # A command reaches its robot and the recorder.
    command_subscribers: int = 2
    # The skill polls the shadow until acknowledged (about four reads), each document
    # with its metadata is 1-2 KB: 2 units per read.
    shadow_reads_per_skill_request: float = 4.0
    shadow_units_per_read: int = 2
    skill_seconds: float = 0.7
    skill_memory_gb: float = 0.5
    log_bytes_per_skill_request: int = 2_000
    # The audit trail: each skill request is one record, appended with a strongly
    # consistent read of the head (1 read unit) and one transaction of two puts under 1 KB
    # (a transaction bills twice: 4 write units).
    audit_reads_per_record: float = 1.0
    audit_writes_per_record: float = 4.0
    # Per robot per lab day: CONNECT, retained presence (publish + retained), twelve
    # SUBSCRIBEs, and the last will on shutdown.
    session_messages_per_robot_day: int = 17


@dataclass(frozen=True)
class Line:
    item: str
    quantity: float
    unit: str
    cost: float


def estimate(usage: LabUsage, prices: Prices, *, lex: bool, skill: bool) -> list[Line]:
    """One line per billable dimension."""
    sessions = usage.voice_sessions + usage.keyboard_sessions
    deliveries = sessions * usage.deliveries_per_session
    skill_requests = usage.voice_sessions * usage.skill_requests_per_voice_session
    commands = sessions * usage.deliveries_per_session  # one command per delivery
    connection_minutes = (
        usage.robots * usage.lab_days * usage.robot_hours_per_day * 60
        + sessions * usage.session_minutes  # the experiment recorder
    )
    # Every metered message: an inbound PUBLISH (or HTTP publish) counts once, each
    # delivery to a QoS 1 subscriber twice (the PUBLISH out and the device's PUBACK).
    messages = (
        commands * (1 + 2 * usage.command_subscribers)
        + deliveries * usage.events_per_delivery * (1 + 2 * usage.event_subscribers)
        # A shadow update over MQTT: the request in (robots do not subscribe to
        # update/accepted, and nothing else does on AWS).
        + deliveries * usage.shadow_updates_per_delivery
        + usage.robots * usage.lab_days * usage.session_messages_per_robot_day
    )
    presence_changes = usage.robots * usage.lab_days * 2  # online in the morning, offline
    shadow_units = (
        deliveries * usage.shadow_updates_per_delivery
        + skill_requests * usage.shadow_reads_per_skill_request * usage.shadow_units_per_read
        + presence_changes  # the presence rule's shadow update
        + sessions  # the experiment plan written to the experiment thing's shadow
    )
    gb_seconds = skill_requests * usage.skill_seconds * usage.skill_memory_gb
    audit_units = skill_requests * (usage.audit_reads_per_record + usage.audit_writes_per_record)
    lines = [
        Line("IoT connectivity", connection_minutes, "connection-minutes",
             connection_minutes * prices.connection_minute),
        Line("IoT messages", messages, "messages (5 KB)", messages * prices.message),
        Line("Device Shadow operations", shadow_units, "operations (1 KB)",
             shadow_units * prices.shadow_operation),
        Line("Rules (presence)", presence_changes, "rules + actions",
             presence_changes * (prices.rule_triggered + prices.rule_action)),
        Line("Lambda requests", skill_requests, "requests", skill_requests * prices.lambda_request),
        Line("Lambda compute", gb_seconds, "GB-seconds", gb_seconds * prices.lambda_gb_second),
        Line("CloudWatch Logs", skill_requests * usage.log_bytes_per_skill_request / 1e9,
             "GB ingested",
             skill_requests * usage.log_bytes_per_skill_request / 1e9 * prices.log_ingestion_gb),
        Line("DynamoDB (audit trail)", audit_units, "request units",
             skill_requests * (usage.audit_reads_per_record * prices.dynamodb_read
                               + usage.audit_writes_per_record * prices.dynamodb_write)),
    ]  # fmt: skip
    if lex:
        questions = sessions * usage.weather_questions_per_session
        lines.append(
            Line("Lex text requests", questions, "requests", questions * prices.lex_text_request)
        )
    if skill:
        lines.append(Line("Secrets Manager", 1, "secret-month", prices.secret_month))
    return lines


# -- the announcer (infra/constructs/announcer.py) ----------------------------------------


@dataclass(frozen=True)
class AnnouncerUsage:
    """One announcer invocation: the rule fires on a fault-related event (never on progress),
    the function reads and writes its state item (under 1 KB) and, on a cold start, reads
    its secret; each announcement is also published for the operator station. Alexa's
    Proactive Events API itself is free."""

    function_seconds: float = 0.3  # token cached; one HTTPS request to Alexa
    memory_gb: float = 0.25
    log_bytes: int = 1_000
    cold_start_share: float = 0.1  # of invocations that read the secret again
    # Events the rule passes per announcement: the fault itself, the failed that ends a
    # stuck task, and the accepted/arrived/done that clear it, all invoking the function.
    invocations_per_announcement: float = 4.0
    # The announcement on vahr/assistant/announcements: its publish and one operator
    # station's delivery, each metered as a message.
    topic_messages: float = 2.0


def announcement_cost(prices: Prices, usage: AnnouncerUsage = AnnouncerUsage()) -> float:
    """USD for one announcement, counting every invocation that leads to it."""
    per_invocation = (
        prices.rule_triggered
        + prices.rule_action
        + prices.lambda_request
        + usage.function_seconds * usage.memory_gb * prices.lambda_gb_second
        + prices.dynamodb_read
        + prices.dynamodb_write
        + usage.log_bytes / 1e9 * prices.log_ingestion_gb
        + usage.cold_start_share * prices.secret_api_call
    )
    return (
        usage.invocations_per_announcement * per_invocation + usage.topic_messages * prices.message
    )


@dataclass(frozen=True)
class AnnouncerTicks:
    """The schedule that wakes the announcer once a minute: each tick reads the state item
    and, with nothing held back, writes nothing. EventBridge does not charge for the
    scheduled events of its rules."""

    per_month: int = 60 * 24 * 30  # once a minute for 30 days
    function_seconds: float = 0.05  # warm: one DynamoDB read
    memory_gb: float = 0.25
    log_bytes: int = 200  # the runtime's start, end and report lines


def announcer_ticks_cost(prices: Prices, ticks: AnnouncerTicks = AnnouncerTicks()) -> float:
    """USD a month for the announcer's schedule alone (announcements cost on top)."""
    per_tick = (
        prices.lambda_request
        + ticks.function_seconds * ticks.memory_gb * prices.lambda_gb_second
        + prices.dynamodb_read
        + ticks.log_bytes / 1e9 * prices.log_ingestion_gb
    )
    return ticks.per_month * per_tick


# -- fleet dispatch and status questions at scale (infra/constructs/dispatcher.py) ------


@dataclass(frozen=True)
class Billable:
    """The billable operations of one action on AWS, by kind."""

    index_queries: float = 0.0  # fleet indexing queries
    index_updates: float = 0.0  # fleet indexing updates (1 KB)
    shadow_operations: float = 0.0  # Device Shadow operations (1 KB)
    dynamodb_reads: float = 0.0  # read request units
    dynamodb_writes: float = 0.0  # write request units
    lambda_requests: float = 0.0
    rules_triggered: float = 0.0
    rule_actions: float = 0.0
    messages: float = 0.0  # IoT Core messages (5 KB)

    def operations(self) -> float:
        return math.fsum(getattr(self, field) for field in self.__dataclass_fields__)

    def cost(self, prices: Prices) -> float:
        return math.fsum(
            (
                self.index_queries * prices.fleet_index_query,
                self.index_updates * prices.fleet_index_update,
                self.shadow_operations * prices.shadow_operation,
                self.dynamodb_reads * prices.dynamodb_read,
                self.dynamodb_writes * prices.dynamodb_write,
                self.lambda_requests * prices.lambda_request,
                self.rules_triggered * prices.rule_triggered,
                self.rule_actions * prices.rule_action,
                self.messages * prices.message,
            )
        )


@dataclass(frozen=True)
class DispatchUsage:
    """One dispatched task on AWS: the skill invokes the dispatcher to submit it, the
    dispatcher finds candidates and assigns it in the task table, publishes the command,
    and the robot's shadow updates while it works reach the dispatcher's rule, the last of
    them (idle, task done) the function, which closes the task."""

    # Task-table request units of a submit and of the robot-freed event that closes the
    # task, measured on the handler under moto (tests/support/dispatch_meter.py; checked by
    # tests/unit/dispatcher/test_dispatcher_costs.py). The submit: the task's PutItem (1
    # write), the assignment's transaction of two items (4: transactions bill twice), two
    # consistent Queries of the open tasks, one of the closed zones, one of the robots'
    # claims (the fleet search skips robots holding a task), one of the robots out of
    # service and a GetItem (6 reads); the robot-freed event: the closing transaction of
    # three items (6 writes), four Queries (one of them the robots out of service) and a
    # GetItem (5).
    table_reads: float = 11.0
    table_writes: float = 11.0
    # The schedule's look at the task once its robot has it (lambda/dispatcher/reoffer.py):
    # the acknowledgment marked on the task's item (an UpdateItem, 1 write) and the robot
    # found in the index (one SearchIndex query, shared by the up to about 40 tasks of one
    # minute: one per task at most). The tick's own reads are the tick's
    # (`announcer_ticks_cost`, the same schedule).
    ack_writes: float = 1.0
    ack_searches: float = 1.0
    # The robot's shadow updates while it does one task (LabUsage: a delivery sends 9).
    # Each is a rule triggered (the rule's topic filter matches every classic shadow's
    # documents; counted whether or not WHERE selects it) and an index update (a robot's
    # reported state is under 1 KB).
    shadow_updates: int = 9
    # SearchIndex calls of a submit: the first page of connected idle robots holds a free
    # one (lambda/dispatcher/fleet_search.py reads further only when it does not), so one
    # whatever the fleet's size; reading every free robot would be one per 100 of them.
    search_pages: int = 1
    # Reading a robot's shadow instead (GetThingShadow): a document with metadata, 1-2 KB.
    shadow_units_per_read: int = 2
    # The command: in once, out to its robot at QoS 1 (the PUBLISH and the PUBACK).
    command_messages: int = 3


def dispatch_billable(
    robots: int, *, index: bool, usage: DispatchUsage = DispatchUsage()
) -> Billable:
    """One dispatched task among `robots`: candidates from fleet indexing (`index`) or by
    reading every robot's shadow."""
    common = {
        "dynamodb_reads": usage.table_reads,
        "dynamodb_writes": usage.table_writes + usage.ack_writes,
        "lambda_requests": 2.0,  # the skill's submit, the robot-freed event
        "rules_triggered": float(usage.shadow_updates),
        "rule_actions": 1.0,
        "messages": float(usage.command_messages),
    }
    if not index:
        # The candidates, and the schedule's look at the task's robot, by shadow reads.
        reads = (robots + usage.ack_searches) * usage.shadow_units_per_read
        return Billable(shadow_operations=reads, **common)
    return Billable(
        index_queries=float(usage.search_pages) + usage.ack_searches,
        index_updates=float(usage.shadow_updates),
        **common,
    )


# The skill's status summary on fleet indexing (lambda/skill/iot_fleet_index.py): counts by
# status (GetBucketsAggregation), robots offline (GetStatistics) and one page of the robots
# it names (SearchIndex).
STATUS_INDEX_QUERIES = 3


def status_billable(
    robots: int, *, index: bool, usage: DispatchUsage = DispatchUsage()
) -> Billable:
    """One status question about `robots`: by fleet indexing, or by reading every shadow.
    (Keeping the index costs its updates, counted with the tasks that cause them.)"""
    if index:
        return Billable(index_queries=STATUS_INDEX_QUERIES, lambda_requests=1.0)
    return Billable(shadow_operations=robots * usage.shadow_units_per_read, lambda_requests=1.0)


def dynamodb_units(operation: str, request: dict[str, object]) -> tuple[float, float]:
    """(read, write) request units an on-demand table bills for one call, by DynamoDB's
    metering: a write 1 unit per KB of the item, twice in a transaction; a strongly
    consistent read 1 unit per 4 KB (a Query over the sum of what it returns; at least
    one). For reads the size comes from the response, passed as `request["_returned"]`."""

    def size(item: object) -> int:
        import json

        return len(json.dumps(item, separators=(",", ":")).encode())

    if operation in ("PutItem", "DeleteItem", "UpdateItem"):
        item = request.get("Item") or request.get("Key")
        return 0.0, float(max(1, math.ceil(size(item) / 1024)))
    if operation == "TransactWriteItems":
        writes = 0
        for entry in request.get("TransactItems", []):  # type: ignore[attr-defined]
            body = next(iter(entry.values()))
            writes += 2 * max(1, math.ceil(size(body.get("Item") or body.get("Key")) / 1024))
        return 0.0, float(writes)
    if operation in ("GetItem", "Query"):
        returned = request.get("_returned", [])
        return float(max(1, math.ceil(size(returned) / 4096))), 0.0
    return 0.0, 0.0


# -- cost of measured operations (bench/billable_operations.py) ---------------------------


def operation_cost(kind: str, units: int, usage: LabUsage, prices: Prices) -> float:
    """USD for `units` billing units of one kind the local meter counts (vahr.twin.meter),
    with the metering rules `estimate` applies: a QoS 1 delivery counts twice (the PUBLISH
    out and the PUBACK in); a shadow request over MQTT is a message in besides the shadow
    operation, and a get's answer a delivery to the robot."""
    if kind == "http.publish":  # a command, to its robot(s) and the recorder
        return units * (1 + 2 * usage.command_subscribers) * prices.message
    if kind == "mqtt.robot.event":  # to the peer robot and the recorder
        return units * (1 + 2 * usage.event_subscribers) * prices.message
    if kind == "mqtt.shadow.update":  # the request in; nobody takes update/accepted
        return units * (prices.shadow_operation + prices.message)
    if kind.startswith("mqtt.shadow."):  # the request in, the answer out to the robot
        return units * (prices.shadow_operation + 3 * prices.message)
    if kind.startswith("http.shadow."):
        return units * prices.shadow_operation
    return units * prices.message


def poll_cost(usage: LabUsage, prices: Prices) -> float:
    """USD for one shadow read by a polling robot over MQTT: the get request in, the
    document out to the robot (QoS 1: twice) and the read itself."""
    return 3 * prices.message + usage.shadow_units_per_read * prices.shadow_operation


def idle_hour_cost(
    robots: int, prices: Prices, *, poll_period_s: float | None = None, usage: LabUsage = LabUsage()
) -> float:
    """USD for an hour in which nobody commands anything: the robots stay connected
    (keep-alive pings are free) and, with `poll_period_s`, read their shadows."""
    connected = robots * 60 * prices.connection_minute
    if poll_period_s is None:
        return connected
    return connected + robots * 3600 / poll_period_s * poll_cost(usage, prices)


@dataclass(frozen=True)
class Deployment:
    """A fleet's month: how many robots, connected how long, given how many commands."""

    name: str
    robots: int
    hours_per_month: float
    commands_per_month: float


# The paper's lab: 2 robots, 8 hours on 22 days, 100 sessions of 5 commands (LabUsage).
LAB = Deployment("2-robot lab", robots=2, hours_per_month=22 * 8, commands_per_month=100 * 5)
# A warehouse running around the clock: 1,000 robots, each sent a task every 15 minutes.
WAREHOUSE = Deployment(
    "1,000-robot warehouse",
    robots=1000,
    hours_per_month=30 * 24,
    commands_per_month=1000 * 4 * 24 * 30,
)


def monthly_cost(
    deployment: Deployment,
    command_usd: float,
    prices: Prices,
    *,
    poll_period_s: float | None = None,
    usage: LabUsage = LabUsage(),
) -> float:
    """USD a month: connected hours (and polling) plus `command_usd` per command."""
    idle = idle_hour_cost(deployment.robots, prices, poll_period_s=poll_period_s, usage=usage)
    return deployment.hours_per_month * idle + deployment.commands_per_month * command_usd


def markdown(lines: list[Line]) -> str:
    """The estimate as a Markdown table with a total."""
    rows = ["| item | quantity per month | unit | USD |", "| --- | ---: | --- | ---: |"]
    for line in lines:
        quantity = f"{line.quantity:,.0f}" if line.quantity >= 10 else f"{line.quantity:.3g}"
        rows.append(f"| {line.item} | {quantity} | {line.unit} | {line.cost:.4f} |")
    total = math.fsum(line.cost for line in lines)
    rows.append(f"| **total** | | | **{total:.2f}** |")
    return "\n".join(rows)


FLEET_SIZES = (10, 1_000, 10_000)


def fleet_markdown(prices: Prices, usage: DispatchUsage = DispatchUsage()) -> str:
    """USD per dispatched task and per status question by fleet size, fleet indexing beside
    reading every shadow, as a Markdown table."""
    rows = [
        "| robots | task, index (µUSD) | task, reading shadows (µUSD) | "
        "status question, index (µUSD) | status question, reading shadows (µUSD) |",
        "| ---: | ---: | ---: | ---: | ---: |",
    ]
    for robots in FLEET_SIZES:
        figures = (
            dispatch_billable(robots, index=True, usage=usage),
            dispatch_billable(robots, index=False, usage=usage),
            status_billable(robots, index=True, usage=usage),
            status_billable(robots, index=False, usage=usage),
        )
        cells = " | ".join(f"{billable.cost(prices) * 1e6:,.1f}" for billable in figures)
        rows.append(f"| {robots:,} | {cells} |")
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m infra.cost_estimate", description=__doc__)
    parser.add_argument("--lex", action="store_true", help="robots interpret answers with Lex")
    parser.add_argument("--skill", action="store_true", help="the skill is deployed by CDK")
    parser.add_argument(
        "--fleet", action="store_true", help="per task and status question, by fleet size"
    )
    args = parser.parse_args(argv)
    if args.fleet:
        print(fleet_markdown(Prices()))
        return 0
    print(markdown(estimate(LabUsage(), Prices(), lex=args.lex, skill=args.skill)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
