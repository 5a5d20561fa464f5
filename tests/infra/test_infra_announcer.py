"""The announcer construct: two rules into the function, least privilege, nothing lost;
and the whole app with `-c announcer=true` passing cdk-nag."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk import aws_lambda as lambda_
from aws_cdk.assertions import Template
from synthesis import synth_app
from template_tools import bare_stack, only, resources, role_grants

from infra.config import InfraConfig
from infra.constructs.announcer import Announcer, events_sql, presence_sql
from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path

PREFIX = "arn:aws:us-east-1:123456789012"
URL = "https://api.amazonalexa.com/v1/proactiveEvents/stages/development"
DATA = "a1b2c3d4e5f6g7-ats.iot.us-east-1.amazonaws.com"


@pytest.fixture(scope="module")
def template(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    stack = bare_stack(tmp_path_factory.mktemp("announcer"))
    Announcer(stack, "Announcer", config=InfraConfig(), events_url=URL, data_endpoint=DATA,
              code=lambda_.Code.from_inline("def lambda_handler(e, c): pass"))  # fmt: skip
    return Template.from_stack(stack).to_json()


def test_the_rules_send_faults_and_presence_but_not_progress(template: dict[str, Any]) -> None:
    rules = {
        r["RuleName"]: r["TopicRulePayload"]
        for r in resources(template, "AWS::IoT::TopicRule").values()
    }
    assert set(rules) == {"vahr_announcer_events", "vahr_announcer_presence"}
    assert rules["vahr_announcer_events"]["Sql"] == events_sql()
    assert "event = 'stuck'" in events_sql() and "progress" not in events_sql()
    assert events_sql().startswith("SELECT *, topic(3) AS sender FROM 'vahr/robots/+/events'")
    assert presence_sql() == (
        "SELECT online, at, topic(3) AS sender FROM 'vahr/robots/+/presence' WHERE isBoolean(online)"
    )
    [function_id] = resources(template, "AWS::Lambda::Function")
    for payload in rules.values():
        [action] = payload["Actions"]
        assert action["Lambda"]["FunctionArn"] == f"<{function_id}.Arn>"
        # And what the rule cannot deliver goes to the dead-letter queue
        assert "Sqs" in payload["ErrorAction"]


def test_the_function_runs_the_announcer_with_retries_and_a_dead_letter_queue(
    template: dict[str, Any],
) -> None:
    function = only(template, "AWS::Lambda::Function")
    assert function["Handler"] == "announcer.app.lambda_handler"
    assert function["Runtime"] == "python3.12"
    [queue_id] = resources(template, "AWS::SQS::Queue")
    assert function["DeadLetterConfig"] == {"TargetArn": f"<{queue_id}.Arn>"}
    variables = function["Environment"]["Variables"]
    assert variables["VAHR_PROACTIVE_EVENTS_URL"] == URL
    assert variables["VAHR_ANNOUNCER_SECRET"] == "vahr/skill-messaging"
    assert variables["VAHR_IOT_DATA_ENDPOINT"] == f"https://{DATA}"
    invoke = only(template, "AWS::Lambda::EventInvokeConfig")
    assert invoke["MaximumRetryAttempts"] == 2
    queue = resources(template, "AWS::SQS::Queue")[queue_id]
    assert queue["SqsManagedSseEnabled"] is True and queue["MessageRetentionPeriod"] == 14 * 86400


def test_the_function_may_read_one_secret_keep_its_state_and_publish_one_topic(
    template: dict[str, Any],
) -> None:
    function = only(template, "AWS::Lambda::Function")
    role_id = function["Role"].strip("<>").split(".")[0]
    [table_id] = resources(template, "AWS::DynamoDB::Table")
    [queue_id] = resources(template, "AWS::SQS::Queue")
    [group_id] = resources(template, "AWS::Logs::LogGroup")
    assert role_grants(template, role_id) == {
        ("Allow", "secretsmanager:GetSecretValue",
         "arn:aws:secretsmanager:us-east-1:123456789012:secret:vahr/skill-messaging-??????"),
        ("Allow", "dynamodb:GetItem", f"<{table_id}.Arn>"),
        ("Allow", "dynamodb:PutItem", f"<{table_id}.Arn>"),
        ("Allow", "iot:Publish", "arn:aws:iot:us-east-1:123456789012:topic/vahr/assistant/announcements"),
        ("Allow", "sqs:SendMessage", f"<{queue_id}.Arn>"),
        ("Allow", "logs:CreateLogStream", f"<{group_id}.Arn>"),
        ("Allow", "logs:PutLogEvents", f"<{group_id}.Arn>"),
    }  # fmt: skip
    # And IoT may invoke it only from its own rules, EventBridge only from its schedule
    rules = resources(template, "AWS::IoT::TopicRule")
    [schedule_id] = resources(template, "AWS::Events::Rule")
    permissions = resources(template, "AWS::Lambda::Permission").values()
    assert sorted((p["Principal"], p["SourceArn"]) for p in permissions) == sorted(
        [("iot.amazonaws.com", f"<{rule_id}.Arn>") for rule_id in rules]
        + [("events.amazonaws.com", f"<{schedule_id}.Arn>")]
    )


def test_a_schedule_wakes_the_function_once_a_minute_and_never_piles_up(
    template: dict[str, Any],
) -> None:
    # Given the announcer's EventBridge rule
    schedule = only(template, "AWS::Events::Rule")
    [function_id] = resources(template, "AWS::Lambda::Function")
    # Then it runs once a minute and invokes the announcer function only
    assert schedule["ScheduleExpression"] == "rate(1 minute)"
    assert schedule["State"] == "ENABLED"
    [target] = schedule["Targets"]
    assert target["Arn"] == f"<{function_id}.Arn>"
    # and a tick it could not deliver is dropped, not retried: the next one does its work
    assert target["RetryPolicy"] == {"MaximumRetryAttempts": 0, "MaximumEventAgeInSeconds": 60}


def test_the_app_with_the_announcer_passes_cdk_nag(tmp_path: Path) -> None:
    synthesized = synth_app(tmp_path, announcer="true", alexaRegion="EU", announcerStage="live")
    found = {r["Type"] for r in synthesized.template["Resources"].values()}
    assert {"AWS::DynamoDB::Table", "AWS::SQS::Queue"} <= found
    urls = {
        f["Environment"]["Variables"].get("VAHR_PROACTIVE_EVENTS_URL")
        for f in resources(synthesized.template, "AWS::Lambda::Function").values()
        if "Environment" in f
    }
    assert "https://api.eu.amazonalexa.com/v1/proactiveEvents/" in urls


def test_bad_announcer_settings_stop_synth_in_one_line(tmp_path: Path) -> None:
    with pytest.raises(VahrError, match=r"^announce\.max_per_window: expected `int` >= 1$"):
        synth_app(tmp_path, announcer="true", announce={"max_per_window": 0})
    with pytest.raises(VahrError, match=r"^alexaRegion: 'MARS' must be NA, EU or FE$"):
        synth_app(tmp_path, alexaRegion="mars")
