"""What lets AWS see trouble, and who may act for the stack: every IoT rule role trusts AWS IoT
only for its own rules of this account, AWS IoT logs errors, Device Defender audits daily,
every dead-letter queue and function raises alarms on one encrypted topic, and a skill the
stack creates is the only one that may invoke its function.

One app with every optional part (and the skill created by the stack, its id unknown at
synth), synthesized with cdk-nag on: `synth_app` raises on any finding not acknowledged.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from synthesis import Synthesized, synth_app
from template_tools import ACCOUNT, PARTITION, REGION, grants, only, resolve, resources, role_grants

from infra.constructs.alexa_skill import CREATION_STATEMENT
from infra.constructs.device_audit import CHECKS

if TYPE_CHECKING:
    from pathlib import Path

IOT = f"arn:{PARTITION}:iot:{REGION}:{ACCOUNT}"
EMAIL = "robots@lab.example"


@pytest.fixture(scope="module")
def app(tmp_path_factory: pytest.TempPathFactory) -> Synthesized:
    return synth_app(
        tmp_path_factory.mktemp("trouble"),
        skill="true",
        skillId=None,
        announcer="true",
        dispatcher="true",
        alarmEmail=EMAIL,
        vendorId="M2AAAAAAAAAAAA",
    )


@pytest.fixture(scope="module")
def template(app: Synthesized) -> dict[str, Any]:
    return app.template


def logical_id_of(reference: str) -> str:
    return reference.strip("<>").split(".")[0]


def trust(template: dict[str, Any], role_id: str) -> list[dict[str, Any]]:
    statements: list[dict[str, Any]] = resources(template, "AWS::IAM::Role")[role_id][
        "AssumeRolePolicyDocument"
    ]["Statement"]
    return statements


# -- the roles AWS IoT acts with -----------------------------------------------------------


def test_every_rule_role_trusts_aws_iot_only_for_its_own_rules_of_this_account(
    template: dict[str, Any],
) -> None:
    # Given every topic rule and the roles its actions name
    rules_of: dict[str, set[str]] = {}
    for rule in resources(template, "AWS::IoT::TopicRule").values():
        payload = rule["TopicRulePayload"]
        actions = [*payload["Actions"], payload.get("ErrorAction", {})]
        for action in actions:
            for body in action.values():
                if "RoleArn" in body:
                    role_id = logical_id_of(body["RoleArn"])
                    rules_of.setdefault(role_id, set()).add(f"{IOT}:rule/{rule['RuleName']}")
    # (the presence rule's, the announcer's and the dispatcher's)
    assert len(rules_of) == 3
    for role_id, rule_arns in rules_of.items():
        # Then the role's one trust statement is AWS IoT, for this account and these rules
        [statement] = trust(template, role_id)
        assert statement["Principal"] == {"Service": "iot.amazonaws.com"}
        assert statement["Action"] == "sts:AssumeRole"
        conditions = statement["Condition"]
        assert conditions["StringEquals"] == {"aws:SourceAccount": ACCOUNT}
        source = conditions["ArnEquals"]["aws:SourceArn"]
        assert set(source if isinstance(source, list) else [source]) == rule_arns


def test_no_role_trusts_aws_iot_without_conditions(template: dict[str, Any]) -> None:
    for role_id in resources(template, "AWS::IAM::Role"):
        for statement in trust(template, role_id):
            if statement["Principal"].get("Service") == "iot.amazonaws.com":
                assert statement["Condition"]["StringEquals"] == {"aws:SourceAccount": ACCOUNT}
                assert "aws:SourceArn" in {
                    key
                    for test in ("ArnEquals", "ArnLike")
                    for key in statement["Condition"].get(test, {})
                }, role_id


# -- AWS IoT's own error log ----------------------------------------------------------------


def test_aws_iot_logs_its_errors_with_a_role_that_writes_only_its_log_group(
    template: dict[str, Any],
) -> None:
    logging = only(template, "AWS::IoT::Logging")
    assert (logging["AccountId"], logging["DefaultLogLevel"]) == (ACCOUNT, "ERROR")
    role_id = logical_id_of(logging["RoleArn"])
    [statement] = trust(template, role_id)
    assert statement["Condition"] == {
        "StringEquals": {"aws:SourceAccount": ACCOUNT},
        "ArnLike": {"aws:SourceArn": f"{IOT}:*"},
    }
    [(group_id, group)] = [
        (logical_id, group)
        for logical_id, group in resources(template, "AWS::Logs::LogGroup").items()
        if group.get("LogGroupName") == "AWSIotLogsV2"
    ]
    assert group["RetentionInDays"] == 30
    assert role_grants(template, role_id) == {
        ("Allow", "logs:CreateLogStream", f"<{group_id}.Arn>"),
        ("Allow", "logs:PutLogEvents", f"<{group_id}.Arn>"),
    }


# -- Device Defender ------------------------------------------------------------------------


def test_device_defender_audits_daily_the_three_checks_and_reports_to_the_alarm_topic(
    template: dict[str, Any],
) -> None:
    configuration = only(template, "AWS::IoT::AccountAuditConfiguration")
    assert configuration["AccountId"] == ACCOUNT
    checks = configuration["AuditCheckConfigurations"]
    assert checks == {
        "IotPolicyOverlyPermissiveCheck": {"Enabled": True},
        "DeviceCertificateSharedCheck": {"Enabled": True},
        "ConflictingClientIdsCheck": {"Enabled": True},
    }
    schedule = only(template, "AWS::IoT::ScheduledAudit")
    assert schedule["Frequency"] == "DAILY"
    assert (
        set(schedule["TargetCheckNames"])
        == set(CHECKS)
        == {
            "IOT_POLICY_OVERLY_PERMISSIVE_CHECK",
            "DEVICE_CERTIFICATE_SHARED_CHECK",
            "CONFLICTING_CLIENT_IDS_CHECK",
        }
    )
    # The schedule comes after the checks it names are on
    [schedule_id] = resources(template, "AWS::IoT::ScheduledAudit")
    [configuration_id] = resources(template, "AWS::IoT::AccountAuditConfiguration")
    assert configuration_id in template["Resources"][schedule_id]["DependsOn"]
    # Findings go to the alarm topic, sent by a role that may publish there and nothing else
    [topic_id] = resources(template, "AWS::SNS::Topic")
    [key_id] = resources(template, "AWS::KMS::Key")
    target = configuration["AuditNotificationTargetConfigurations"]["Sns"]
    assert (target["Enabled"], target["TargetArn"]) == (True, f"<{topic_id}>")
    assert role_grants(template, logical_id_of(target["RoleArn"])) == {
        ("Allow", "sns:Publish", f"<{topic_id}>"),
        ("Allow", "kms:GenerateDataKey", f"<{key_id}.Arn>"),
        ("Allow", "kms:Decrypt", f"<{key_id}.Arn>"),
    }
    # And the audit reads with AWS's own audit policy, as AWS IoT for this account only
    audit_role = resources(template, "AWS::IAM::Role")[logical_id_of(configuration["RoleArn"])]
    assert audit_role["ManagedPolicyArns"] == [
        f"arn:{PARTITION}:iam::aws:policy/service-role/AWSIoTDeviceDefenderAudit"
    ]
    assert audit_role["AssumeRolePolicyDocument"]["Statement"][0]["Condition"]["StringEquals"] == {
        "aws:SourceAccount": ACCOUNT
    }


# -- alarms -----------------------------------------------------------------------------------


def test_every_dead_letter_queue_and_every_function_raises_alarms_on_the_topic(
    template: dict[str, Any],
) -> None:
    [topic_id] = resources(template, "AWS::SNS::Topic")
    alarms = resources(template, "AWS::CloudWatch::Alarm").values()
    watched: set[tuple[str, str]] = set()
    for alarm in alarms:
        assert alarm["AlarmActions"] == [f"<{topic_id}>"]
        assert (alarm["Threshold"], alarm["ComparisonOperator"]) == (
            1,
            "GreaterThanOrEqualToThreshold",
        )
        assert alarm["TreatMissingData"] == "notBreaching"
        [dimension] = alarm["Dimensions"]
        watched.add((alarm["MetricName"], logical_id_of(dimension["Value"])))
    queues = set(resources(template, "AWS::SQS::Queue"))
    functions = {
        logical_id
        for logical_id, function in resources(template, "AWS::Lambda::Function").items()
        if function["Handler"].split(".")[0] in ("skill", "announcer", "dispatcher")
    }
    assert len(queues) == 2 and len(functions) == 3
    assert watched == {
        *(("ApproximateNumberOfMessagesVisible", queue) for queue in queues),
        *(("Errors", function) for function in functions),
        *(("Throttles", function) for function in functions),
    }


def test_the_alarm_topic_is_encrypted_takes_tls_only_and_mails_the_given_address(
    template: dict[str, Any],
) -> None:
    topic = only(template, "AWS::SNS::Topic")
    [key_id] = resources(template, "AWS::KMS::Key")
    assert topic["KmsMasterKeyId"] == f"<{key_id}.Arn>"
    key = only(template, "AWS::KMS::Key")
    assert key["EnableKeyRotation"] is True
    # CloudWatch may use the key, for this account's alarms only
    [cloudwatch] = [
        s for s in key["KeyPolicy"]["Statement"] if s.get("Sid") == "CloudWatchAlarmsOfThisAccount"
    ]
    assert cloudwatch["Principal"] == {"Service": "cloudwatch.amazonaws.com"}
    assert cloudwatch["Condition"]["StringEquals"] == {"aws:SourceAccount": ACCOUNT}
    policy = only(template, "AWS::SNS::TopicPolicy")["PolicyDocument"]
    assert any(
        s["Effect"] == "Deny" and s["Condition"] == {"Bool": {"aws:SecureTransport": "false"}}
        for s in policy["Statement"]
    )
    subscription = only(template, "AWS::SNS::Subscription")
    assert (subscription["Protocol"], subscription["Endpoint"]) == ("email", EMAIL)


# -- the skill the stack creates --------------------------------------------------------------


def test_a_skill_the_stack_creates_is_the_only_one_its_function_serves(
    template: dict[str, Any],
) -> None:
    [skill_id] = resources(template, "Alexa::ASK::Skill")
    skill = f"<{skill_id}>"
    alexa = {
        logical_id: permission
        for logical_id, permission in resources(template, "AWS::Lambda::Permission").items()
        if permission["Principal"] == "alexa-appkit.amazon.com"
    }
    # Then the one lasting permission for Alexa carries the new skill's id
    [(permission_id, permission)] = alexa.items()
    assert permission["EventSourceToken"] == skill
    # And the handler reads the same id from the parameter the stack writes
    parameter = only(template, "AWS::SSM::Parameter")
    assert (parameter["Name"], parameter["Value"]) == ("/vahr/Vahr/skill-id", skill)
    skill_function = next(
        function
        for function in resources(template, "AWS::Lambda::Function").values()
        if function["Handler"] == "skill.app.lambda_handler"
    )
    variables = skill_function["Environment"]["Variables"]
    assert variables["VAHR_SKILL_ID_PARAMETER"] == "/vahr/Vahr/skill-id"
    assert "VAHR_ALLOW_ANY_SKILL" not in variables


def test_the_grant_alexas_creation_check_needs_is_added_before_and_removed_after(
    template: dict[str, Any],
) -> None:
    custom = {
        logical_id: resource
        for logical_id, resource in template["Resources"].items()
        if resource["Type"] == "Custom::AWS" and logical_id.startswith("AlexaSkill")
    }
    [opened_id] = [i for i in custom if i.startswith("AlexaSkillAllowSkillCreation")]
    [closed_id] = [i for i in custom if i.startswith("AlexaSkillCloseSkillCreation")]
    opened = str(resolve(custom[opened_id]["Properties"]["Create"]))
    assert '"action":"addPermission"' in opened
    assert f'"StatementId":"{CREATION_STATEMENT}"' in opened
    assert "EventSourceToken" not in opened
    closed = str(resolve(custom[closed_id]["Properties"]["Create"]))
    assert '"action":"removePermission"' in closed
    assert f'"StatementId":"{CREATION_STATEMENT}"' in closed
    # The skill is created after the grant, and the grant removed after the lasting
    # permission and the parameter exist
    [skill_id] = resources(template, "Alexa::ASK::Skill")
    assert opened_id in template["Resources"][skill_id]["DependsOn"]
    [permission_id] = [
        i
        for i, p in resources(template, "AWS::Lambda::Permission").items()
        if p["Principal"] == "alexa-appkit.amazon.com"
    ]
    [parameter_id] = resources(template, "AWS::SSM::Parameter")
    assert {permission_id, parameter_id} <= set(template["Resources"][closed_id]["DependsOn"])
    # And the provider may add and remove permissions on the skill function alone
    policies = [
        p["PolicyDocument"]
        for i, p in resources(template, "AWS::IAM::Policy").items()
        if i.startswith(("AlexaSkillAllowSkillCreation", "AlexaSkillCloseSkillCreation"))
    ]
    assert {(effect, action) for doc in policies for effect, action, _ in grants(doc)} == {
        ("Allow", "lambda:AddPermission"),
        ("Allow", "lambda:RemovePermission"),
    }
    assert len({resource for doc in policies for _, _, resource in grants(doc)}) == 1


def test_logging_and_the_audit_can_be_left_to_another_stack(tmp_path: Path) -> None:
    synthesized = synth_app(tmp_path, iotLogging="false", deviceDefenderAudit="false")
    found = {r["Type"] for r in synthesized.template["Resources"].values()}
    assert not found & {
        "AWS::IoT::Logging", "AWS::IoT::AccountAuditConfiguration", "AWS::IoT::ScheduledAudit",
    }  # fmt: skip
    # The alarms stay: they belong to this stack alone
    assert "AWS::CloudWatch::Alarm" in found


def test_the_dispatcher_may_invoke_the_announcer_alone_to_tell_a_lost_task(
    template: dict[str, Any],
) -> None:
    """A task the dispatcher loses is told through the announcer function: its role may
    invoke that one function (no version, no alias), whose name it is given."""
    by_handler = {
        function["Handler"]: (logical_id, function)
        for logical_id, function in resources(template, "AWS::Lambda::Function").items()
    }
    announcer_id, _ = by_handler["announcer.app.lambda_handler"]
    _, dispatcher = by_handler["dispatcher.app.lambda_handler"]
    assert dispatcher["Environment"]["Variables"]["VAHR_ANNOUNCER_FUNCTION"] == f"<{announcer_id}>"
    invokes = {
        (effect, resource)
        for effect, action, resource in role_grants(template, logical_id_of(dispatcher["Role"]))
        if action == "lambda:InvokeFunction"
    }
    assert invokes == {("Allow", f"<{announcer_id}.Arn>")}
