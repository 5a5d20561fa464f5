"""The dispatcher's constructs on bare stacks (the task table, fleet indexing, the function
with its rule and rights, the skill's admission), and the whole app with
`-c dispatcher=true` passing cdk-nag and cfn-lint."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
import pytest
from aws_cdk import aws_iam as iam
from aws_cdk import aws_lambda as lambda_
from aws_cdk.assertions import Template
from synthesis import synth_app
from template_tools import bare_stack, only, resources, role_grants

from infra.config import InfraConfig
from infra.constructs.dispatcher import Dispatcher, freed_sql
from infra.constructs.fleet_indexing import FleetIndexing
from infra.constructs.task_table import TaskTable
from vahr.domain import load_fleet

if TYPE_CHECKING:
    from synthesis import Synthesized

DATA = "a1b2c3d4e5f6g7-ats.iot.us-east-1.amazonaws.com"
IOT = "arn:aws:iot:us-east-1:123456789012"
INDEX = f"{IOT}:index/AWS_Things"


def table_template(outdir: Path, *, deletion_protection: bool) -> dict[str, Any]:
    stack = bare_stack(outdir)
    TaskTable(stack, "Tasks", deletion_protection=deletion_protection)
    return dict(Template.from_stack(stack).to_json())


def test_the_task_table_is_on_demand_recoverable_encrypted_and_expires_closed_tasks(
    tmp_path: Path,
) -> None:
    template = table_template(tmp_path, deletion_protection=False)
    [(table_id, table)] = resources(template, "AWS::DynamoDB::Table").items()
    # The key schema lambda/dispatcher/task_table.py reads and writes
    assert table["KeySchema"] == [
        {"AttributeName": "section", "KeyType": "HASH"},
        {"AttributeName": "id", "KeyType": "RANGE"},
    ]
    assert table["BillingMode"] == "PAY_PER_REQUEST"
    assert table["PointInTimeRecoverySpecification"] == {"PointInTimeRecoveryEnabled": True}
    assert table["SSESpecification"] == {"SSEEnabled": True}
    assert table["TimeToLiveSpecification"] == {"AttributeName": "expires_at", "Enabled": True}
    assert table.get("DeletionProtectionEnabled", False) is False
    assert template["Resources"][table_id]["DeletionPolicy"] == "Delete"


def test_deletion_protection_also_keeps_the_table_when_the_stack_goes(tmp_path: Path) -> None:
    template = table_template(tmp_path, deletion_protection=True)
    [(table_id, table)] = resources(template, "AWS::DynamoDB::Table").items()
    assert table["DeletionProtectionEnabled"] is True
    assert template["Resources"][table_id]["DeletionPolicy"] == "Retain"


@pytest.fixture(scope="module")
def indexing_template(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    stack = bare_stack(tmp_path_factory.mktemp("indexing"))
    logs = cdk.aws_logs.LogGroup(stack, "ProviderLogs")
    FleetIndexing(stack, "FleetIndexing", provider_logs=logs)
    return dict(Template.from_stack(stack).to_json())


def test_fleet_indexing_indexes_shadows_with_status_and_zone_and_is_off_after_delete(
    indexing_template: dict[str, Any],
) -> None:
    import json

    [resource] = resources(indexing_template, "Custom::AWS").values()
    create = json.loads(resource["Create"])
    assert (create["service"], create["action"]) == ("Iot", "updateIndexingConfiguration")
    assert create["parameters"] == {
        "thingIndexingConfiguration": {
            "thingIndexingMode": "REGISTRY_AND_SHADOW",
            "thingConnectivityIndexingMode": "OFF",
            "customFields": [
                {"name": "shadow.reported.status", "type": "String"},
                {"name": "shadow.reported.zone", "type": "String"},
                {"name": "shadow.reported.connected", "type": "Boolean"},
                {"name": "shadow.reported.battery.percent", "type": "Number"},
                {"name": "shadow.reported.battery.charging", "type": "Boolean"},
            ],
        }
    }
    assert json.loads(resource["Update"])["parameters"] == create["parameters"]
    delete = json.loads(resource["Delete"])
    assert delete["parameters"] == {"thingIndexingConfiguration": {"thingIndexingMode": "OFF"}}
    # The provider may call that one action and nothing else
    policy = only(indexing_template, "AWS::IAM::Policy")
    [statement] = policy["PolicyDocument"]["Statement"]
    assert (statement["Action"], statement["Resource"]) == (
        "iot:UpdateIndexingConfiguration",
        "*",
    )


@pytest.fixture(scope="module")
def dispatcher_template(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    stack = bare_stack(tmp_path_factory.mktemp("dispatcher"))
    tasks = TaskTable(stack, "Tasks", deletion_protection=False)
    code = lambda_.Code.from_inline("def lambda_handler(e, c): pass")
    dispatcher = Dispatcher(
        stack,
        "Dispatcher",
        config=InfraConfig(),
        fleet=load_fleet(),
        code=code,
        table=tasks.table,
        index_arn=INDEX,
        data_endpoint=DATA,
    )
    skill_role = iam.Role(
        stack, "SkillRole", assumed_by=iam.ServicePrincipal("lambda.amazonaws.com")
    )
    skill = lambda_.Function(
        stack, "Skill", runtime=lambda_.Runtime.PYTHON_3_12, handler="skill.app.lambda_handler",
        code=code, role=skill_role,
    )  # fmt: skip
    dispatcher.admit_skill(skill, skill_role)
    return dict(Template.from_stack(stack).to_json())


def functions(template: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {
        props["Handler"]: {"id": logical_id, **props}
        for logical_id, props in resources(template, "AWS::Lambda::Function").items()
    }


def test_the_rule_reads_shadow_documents_into_the_function_and_dead_letters_failures(
    dispatcher_template: dict[str, Any],
) -> None:
    rule = only(dispatcher_template, "AWS::IoT::TopicRule")
    assert rule["RuleName"] == "vahr_dispatcher_robot_freed"
    payload = rule["TopicRulePayload"]
    assert payload["Sql"] == freed_sql()
    assert payload["AwsIotSqlVersion"] == "2016-03-23"
    assert "FROM '$aws/things/+/shadow/update/documents'" in freed_sql()
    function = functions(dispatcher_template)["dispatcher.app.lambda_handler"]
    [action] = payload["Actions"]
    assert action["Lambda"]["FunctionArn"] == f"<{function['id']}.Arn>"
    [queue_id] = resources(dispatcher_template, "AWS::SQS::Queue")
    assert payload["ErrorAction"]["Sqs"]["QueueUrl"] == f"<{queue_id}>"
    # And IoT may invoke the function from this rule only
    [permission] = [
        p
        for p in resources(dispatcher_template, "AWS::Lambda::Permission").values()
        if p["Principal"] == "iot.amazonaws.com"
    ]
    [rule_id] = resources(dispatcher_template, "AWS::IoT::TopicRule")
    assert permission["SourceArn"] == f"<{rule_id}.Arn>"


def test_a_schedule_wakes_the_function_once_a_minute_and_never_piles_up(
    dispatcher_template: dict[str, Any],
) -> None:
    schedule = only(dispatcher_template, "AWS::Events::Rule")
    function = functions(dispatcher_template)["dispatcher.app.lambda_handler"]
    assert schedule["ScheduleExpression"] == "rate(1 minute)"
    [target] = schedule["Targets"]
    assert target["Arn"] == f"<{function['id']}.Arn>"
    assert target["RetryPolicy"] == {"MaximumRetryAttempts": 0, "MaximumEventAgeInSeconds": 60}
    # And EventBridge may invoke the function from this schedule only
    [schedule_id] = resources(dispatcher_template, "AWS::Events::Rule")
    [permission] = [
        p
        for p in resources(dispatcher_template, "AWS::Lambda::Permission").values()
        if p["Principal"] == "events.amazonaws.com"
    ]
    assert permission["SourceArn"] == f"<{schedule_id}.Arn>"


def test_the_function_retries_then_dead_letters_and_knows_its_table_and_index(
    dispatcher_template: dict[str, Any],
) -> None:
    function = functions(dispatcher_template)["dispatcher.app.lambda_handler"]
    assert function["Runtime"] == "python3.12"
    [queue_id] = resources(dispatcher_template, "AWS::SQS::Queue")
    assert function["DeadLetterConfig"] == {"TargetArn": f"<{queue_id}.Arn>"}
    invoke = only(dispatcher_template, "AWS::Lambda::EventInvokeConfig")
    assert invoke["MaximumRetryAttempts"] == 2
    [table_id] = resources(dispatcher_template, "AWS::DynamoDB::Table")
    assert function["Environment"]["Variables"] == {
        "VAHR_TASK_TABLE": f"<{table_id}>",
        "VAHR_FLEET_INDEX": "AWS_Things",
        "VAHR_IOT_DATA_ENDPOINT": f"https://{DATA}",
        "VAHR_LOG_LEVEL": "INFO",
    }
    queue = resources(dispatcher_template, "AWS::SQS::Queue")[queue_id]
    assert queue["SqsManagedSseEnabled"] is True and queue["MessageRetentionPeriod"] == 14 * 86400


def test_the_function_may_keep_tasks_search_the_index_and_command_the_fleet_only(
    dispatcher_template: dict[str, Any],
) -> None:
    function = functions(dispatcher_template)["dispatcher.app.lambda_handler"]
    role_id = function["Role"].strip("<>").split(".")[0]
    [table_id] = resources(dispatcher_template, "AWS::DynamoDB::Table")
    [queue_id] = resources(dispatcher_template, "AWS::SQS::Queue")
    [group_id] = [
        logical_id
        for logical_id in resources(dispatcher_template, "AWS::Logs::LogGroup")
        if logical_id.startswith("DispatcherLogs")
    ]
    table = f"<{table_id}.Arn>"
    assert role_grants(dispatcher_template, role_id) == {
        ("Allow", "dynamodb:GetItem", table),
        ("Allow", "dynamodb:PutItem", table),
        ("Allow", "dynamodb:DeleteItem", table),
        ("Allow", "dynamodb:UpdateItem", table),
        ("Allow", "dynamodb:Query", table),
        ("Allow", "iot:SearchIndex", INDEX),
        ("Allow", "iot:Publish", f"{IOT}:topic/vahr/robots/placebot1/cmd"),
        ("Allow", "iot:Publish", f"{IOT}:topic/vahr/robots/placebot2/cmd"),
        ("Allow", "iot:Publish", f"{IOT}:topic/vahr/fleet/zones"),
        ("Allow", "iot:RetainPublish", f"{IOT}:topic/vahr/fleet/zones"),
        ("Allow", "sqs:SendMessage", f"<{queue_id}.Arn>"),
        ("Allow", "logs:CreateLogStream", f"<{group_id}.Arn>"),
        ("Allow", "logs:PutLogEvents", f"<{group_id}.Arn>"),
    }


def test_the_skill_may_invoke_the_dispatcher_and_ask_the_index_and_knows_both(
    dispatcher_template: dict[str, Any],
) -> None:
    dispatcher = functions(dispatcher_template)["dispatcher.app.lambda_handler"]
    skill = functions(dispatcher_template)["skill.app.lambda_handler"]
    assert role_grants(dispatcher_template, "SkillRole") == {
        ("Allow", "lambda:InvokeFunction", f"<{dispatcher['id']}.Arn>"),
        ("Allow", "iot:SearchIndex", INDEX),
        ("Allow", "iot:GetBucketsAggregation", INDEX),
        ("Allow", "iot:GetStatistics", INDEX),
    }
    assert skill["Environment"]["Variables"] == {
        "VAHR_DISPATCHER_FUNCTION": f"<{dispatcher['id']}>",
        "VAHR_FLEET_INDEX": "AWS_Things",
    }


@pytest.fixture(scope="module")
def dispatch_app(tmp_path_factory: pytest.TempPathFactory) -> Synthesized:
    return synth_app(tmp_path_factory.mktemp("dispatch"), dispatcher="true")


def test_the_app_with_the_dispatcher_passes_cdk_nag_and_wires_the_skill(
    dispatch_app: Synthesized,
) -> None:
    template = dispatch_app.template
    found = {r["Type"] for r in template["Resources"].values()}
    assert {"AWS::DynamoDB::Table", "AWS::IoT::TopicRule", "Custom::AWS"} <= found
    handlers = functions(template)
    skill = handlers["skill.app.lambda_handler"]
    dispatcher = handlers["dispatcher.app.lambda_handler"]
    assert skill["Environment"]["Variables"]["VAHR_DISPATCHER_FUNCTION"] == f"<{dispatcher['id']}>"
    assert {"DispatcherFunctionName", "TaskTableName"} <= set(template["Outputs"])


def test_the_lean_app_has_no_dispatcher(lean_app: Synthesized) -> None:
    handlers = functions(lean_app.template)
    assert "dispatcher.app.lambda_handler" not in handlers
    assert (
        "VAHR_DISPATCHER_FUNCTION"
        not in handlers["skill.app.lambda_handler"]["Environment"]["Variables"]
    )
    # No task table (the audit table is the only one)
    tables = resources(lean_app.template, "AWS::DynamoDB::Table").values()
    assert [table["KeySchema"][0]["AttributeName"] for table in tables] == ["trail"]


def test_cfn_lint_passes_with_the_dispatcher(dispatch_app: Synthesized) -> None:
    cfn_lint = Path(sys.executable).parent / "cfn-lint"
    # W3005 (a redundant DependsOn) is what CDK emits for explicit dependencies.
    result = subprocess.run(
        [str(cfn_lint), "--ignore-checks", "W3005", "--", str(dispatch_app.file)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr


def test_a_bad_deletion_protection_flag_is_one_line() -> None:
    from vahr.errors import VahrError

    context = {"taskTableDeletionProtection": "maybe"}
    with pytest.raises(
        VahrError, match=r"^taskTableDeletionProtection: 'maybe' is not true or false$"
    ):
        InfraConfig.from_context(context.get)
