"""The dispatcher's role grants what its code does, and nothing it does not: every AWS call
the real handler makes for a task (its submit, and the event that closes it) is allowed by
the synthesized role, and every right the role holds is used."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk import aws_lambda as lambda_
from aws_cdk.assertions import Template
from moto import mock_aws
from template_tools import bare_stack, resources, role_grants

from infra.config import InfraConfig
from infra.constructs.dispatcher import Dispatcher
from infra.constructs.task_table import TaskTable
from tests.support.dispatch_meter import (
    ANNOUNCER,
    measure_dispatch,
    measure_lost_task,
    measure_service_and_charge,
    measure_zone_change,
)
from tests.support.fleets import THREE_ROVERS
from vahr.domain import load_fleet

if TYPE_CHECKING:
    from pathlib import Path

IOT = "arn:aws:iot:us-east-1:123456789012"
ANNOUNCER_ARN = f"arn:aws:lambda:us-east-1:123456789012:function:{ANNOUNCER}"
INDEX = f"{IOT}:index/AWS_Things"
# A transaction is authorized as the writes in it.
TRANSACTION_PARTS = {"Put": "PutItem", "Delete": "DeleteItem", "Update": "UpdateItem",
                     "ConditionCheck": "ConditionCheckItem"}  # fmt: skip


def needed(
    service: str, operation: str, params: dict[str, Any], table: str
) -> set[tuple[str, str]]:
    """The (action, resource) pairs IAM checks for one call."""
    if service == "dynamodb" and operation == "TransactWriteItems":
        return {
            (f"dynamodb:{TRANSACTION_PARTS[kind]}", table)
            for item in params["TransactItems"]
            for kind in item
        }
    if service == "dynamodb":
        return {(f"dynamodb:{operation}", table)}
    if operation == "SearchIndex":
        return {("iot:SearchIndex", f"{IOT}:index/{params.get('indexName', 'AWS_Things')}")}
    if operation == "Invoke":
        return {("lambda:InvokeFunction", ANNOUNCER_ARN)}
    if operation == "Publish":
        topic = f"{IOT}:topic/{params['topic']}"
        if params.get("retain"):
            return {("iot:Publish", topic), ("iot:RetainPublish", topic)}
        return {("iot:Publish", topic)}
    raise AssertionError(f"an unexpected call: {service} {operation}")


@pytest.fixture
def credentials(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY"):
        monkeypatch.setenv(name, "testing")
    monkeypatch.setenv("AWS_DEFAULT_REGION", "us-east-1")
    for name in ("AWS_ENDPOINT_URL", "AWS_ENDPOINT_URL_IOT", "AWS_ENDPOINT_URL_IOT_DATA_PLANE"):
        monkeypatch.delenv(name, raising=False)


def test_every_call_of_a_task_is_allowed_and_every_right_is_used(
    tmp_path: Path, credentials: None
) -> None:
    # Given the dispatcher's role as the stack synthesizes it, beside the announcer
    stack = bare_stack(tmp_path)
    tasks = TaskTable(stack, "Tasks", deletion_protection=False)
    Dispatcher(
        stack, "Dispatcher", config=InfraConfig(), fleet=load_fleet(),
        code=lambda_.Code.from_inline("def lambda_handler(e, c): pass"),
        table=tasks.table, index_arn=INDEX, data_endpoint="x-ats.iot.us-east-1.amazonaws.com",
        announcer=lambda_.Function.from_function_arn(stack, "Announcer", ANNOUNCER_ARN),
    )  # fmt: skip
    template = Template.from_stack(stack).to_json()
    [table_id] = resources(template, "AWS::DynamoDB::Table")
    table = f"<{table_id}.Arn>"
    [role_id] = [
        f["Role"].strip("<>").split(".")[0]
        for f in resources(template, "AWS::Lambda::Function").values()
    ]
    granted = {
        (action, resource)
        for effect, action, resource in role_grants(template, role_id)
        if effect == "Allow" and not action.startswith(("logs:", "sqs:"))
    }
    # When the real handler dispatches a task to placebot1 or placebot2 and closes it,
    # (on another table) closes a zone, and (on a third) offers a task again and loses it
    with mock_aws():
        measured = measure_dispatch(2)
    with mock_aws():
        zone_change = measure_zone_change()
    with mock_aws(config={"lambda": {"use_docker": False}}):
        lost = measure_lost_task()
    used: set[tuple[str, str]] = set()
    for meter in (measured.submit, measured.freed, zone_change, lost):
        for service, operation, params in meter.requests:
            used |= needed(service, operation, params, table)
    # Then each call is allowed
    assert used <= granted, sorted(used - granted)
    # And each right is used, but publishing to the robot that did not take this task
    publish_rights = {(a, r) for a, r in granted if a == "iot:Publish"}
    assert granted - publish_rights <= used, sorted(granted - publish_rights - used)
    assert ("iot:Publish", f"{IOT}:topic/vahr/robots/{measured.assigned_to}/cmd") in used
    assert ("lambda:InvokeFunction", ANNOUNCER_ARN) in granted
    assert publish_rights == {
        ("iot:Publish", f"{IOT}:topic/vahr/robots/{thing}/cmd")
        for thing in load_fleet().robot_things
    } | {("iot:Publish", f"{IOT}:topic/vahr/fleet/zones")}


@pytest.mark.parametrize("fleet_file", [None, str(THREE_ROVERS)], ids=["bundled", "charger"])
def test_robots_out_of_service_and_charging_need_no_new_right(
    tmp_path: Path, credentials: None, fleet_file: str | None
) -> None:
    # Given the dispatcher's role as the stack synthesizes it for a fleet (one with a
    # charger and batteries: its chargers are held in the task table)
    stack = bare_stack(tmp_path)
    tasks = TaskTable(stack, "Tasks", deletion_protection=False)
    Dispatcher(
        stack, "Dispatcher", config=InfraConfig(), fleet=load_fleet(fleet_file),
        code=lambda_.Code.from_inline("def lambda_handler(e, c): pass"),
        table=tasks.table, index_arn=INDEX, data_endpoint="x-ats.iot.us-east-1.amazonaws.com",
    )  # fmt: skip
    template = Template.from_stack(stack).to_json()
    [table_id] = resources(template, "AWS::DynamoDB::Table")
    [role_id] = [
        f["Role"].strip("<>").split(".")[0]
        for f in resources(template, "AWS::Lambda::Function").values()
    ]
    granted = {
        (action, resource)
        for effect, action, resource in role_grants(template, role_id)
        if effect == "Allow"
    }
    # When the real handler takes a robot out of service and back, sends one to charge
    # and ticks with a low robot idle
    with mock_aws():
        meter = measure_service_and_charge(fleet_file)
    used: set[tuple[str, str]] = set()
    for service, operation, params in meter.requests:
        used |= needed(service, operation, params, f"<{table_id}.Arn>")
    # Then each call is allowed by the rights it already had
    assert used <= granted, sorted(used - granted)
