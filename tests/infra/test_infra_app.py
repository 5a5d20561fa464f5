"""The whole app: optional parts only when enabled, outputs, cdk-nag and cfn-lint clean."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import aws_cdk as cdk
import pytest
from aws_cdk import aws_iam as iam
from aws_cdk.assertions import Template
from synthesis import Synthesized, synth_app
from template_tools import SKILL_ID, cdk_context, only, resources

from infra.app import build_app
from vahr.errors import VahrError

if TYPE_CHECKING:
    from vahr.domain import Fleet

OPTIONAL_TYPES = ("Alexa::ASK::Skill", "AWS::Lex::Bot", "AWS::Lex::BotAlias", "AWS::IoT::RoleAlias")


def types(synthesized: Synthesized) -> set[str]:
    return {resource["Type"] for resource in synthesized.template["Resources"].values()}


def test_the_lean_app_has_the_core_and_no_optional_parts(lean_app: Synthesized) -> None:
    found = types(lean_app)
    assert {"AWS::IoT::Thing", "AWS::IoT::ThingGroup", "AWS::IoT::Policy",
            "AWS::IoT::TopicRule", "AWS::Lambda::Function"} <= found  # fmt: skip
    assert not found & set(OPTIONAL_TYPES)
    assert set(lean_app.template["Outputs"]) == {
        "IotDataEndpoint", "SkillFunctionArn", "ThingNames", "ExperimentThing", "RobotPolicyName",
        "StationPolicyName", "RecorderPolicyName", "AlarmTopicArn", "AuditTableName",
    }  # fmt: skip
    # What lets AWS see trouble is part of the core
    assert {"AWS::IoT::Logging", "AWS::IoT::AccountAuditConfiguration",
            "AWS::IoT::ScheduledAudit", "AWS::CloudWatch::Alarm", "AWS::SNS::Topic"} <= found  # fmt: skip


def test_the_full_app_adds_the_skill_the_bot_and_the_role_alias(full_app: Synthesized) -> None:
    assert set(OPTIONAL_TYPES) <= types(full_app)
    assert {
        "RoleAlias", "CredentialsEndpoint", "BotId", "BotAliasId", "SkillId", "UsersTableName",
    } <= set(full_app.template["Outputs"])  # fmt: skip
    # The robot policy gains the right to use the role alias
    policy = next(
        p["PolicyDocument"]
        for p in resources(full_app.template, "AWS::IoT::Policy").values()
        if p["PolicyName"] == "vahr-robot-policy"
    )
    assert "ExchangeCertificateForLexCredentials" in {s["Sid"] for s in policy["Statement"]}


def test_outputs_name_what_robots_and_the_ask_path_need(
    lean_app: Synthesized, fleet: Fleet
) -> None:
    outputs = lean_app.template["Outputs"]
    assert outputs["ThingNames"]["Value"] == ",".join(fleet.robot_things)
    assert outputs["ExperimentThing"]["Value"] == fleet.experiment_thing
    assert outputs["RobotPolicyName"]["Value"] == "vahr-robot-policy"
    assert outputs["SkillFunctionArn"]["Value"]["Fn::GetAtt"][1] == "Arn"


def test_the_skill_is_created_from_the_package_with_the_function_as_endpoint(
    full_app: Synthesized,
) -> None:
    skill = only(full_app.template, "Alexa::ASK::Skill")
    [function_id] = resources(full_app.template, "AWS::Lambda::Function").keys() - {
        logical_id
        for logical_id in full_app.template["Resources"]
        if logical_id.startswith("AWS679f53fac002430cb0da5b7982bd2287")
    }
    assert skill["SkillPackage"]["Overrides"] == {
        "Manifest": {"apis": {"custom": {"endpoint": {"uri": f"<{function_id}.Arn>"}}}}
    }
    # Login-with-Amazon credentials are resolved from Secrets Manager at deploy time
    auth = skill["AuthenticationConfiguration"]
    assert auth["RefreshToken"] == "{{resolve:secretsmanager:vahr/lwa:SecretString:refreshToken::}}"
    assert skill["VendorId"] == "{{resolve:secretsmanager:vahr/lwa:SecretString:vendorId::}}"
    # Only the deployed skill may invoke the function
    permission = only(full_app.template, "AWS::Lambda::Permission")
    assert permission["EventSourceToken"] == SKILL_ID


@pytest.mark.parametrize("app", ["lean_app", "full_app"])
def test_cfn_lint_passes_on_the_synthesized_template(
    app: str, request: pytest.FixtureRequest
) -> None:
    synthesized: Synthesized = request.getfixturevalue(app)
    cfn_lint = Path(sys.executable).parent / "cfn-lint"
    # W3005 (a redundant DependsOn) is what CDK emits for explicit dependencies.
    result = subprocess.run(
        [str(cfn_lint), "--ignore-checks", "W3005", "--", str(synthesized.file)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr


def test_cdk_nag_fails_synth_on_an_unacknowledged_finding_and_lists_the_accepted_ones(
    tmp_path: Path,
) -> None:
    # Given the app with one more role that may do anything on anything
    app = cdk.App(context=cdk_context(), outdir=str(tmp_path))
    stack = build_app(app)
    loose = iam.Role(stack, "Loose", assumed_by=iam.ServicePrincipal("lambda.amazonaws.com"))
    loose.add_to_policy(iam.PolicyStatement(actions=["iot:*"], resources=["*"]))
    # When it is synthesized, Then cdk-nag stops it
    with pytest.raises(RuntimeError, match="ValidationFailed"):
        Template.from_stack(stack)
    reports = json.loads((tmp_path / "validation-report.json").read_text())["pluginReports"]
    [report] = [r for r in reports if r["pluginName"] == "AwsSolutions"]
    # And the only violations are that role's wildcards
    violations = {
        (v["ruleName"], c["constructPath"])
        for v in report["violations"]
        for c in v["violatingConstructs"]
    }
    assert violations == {
        ("AwsSolutions-IAM5[Resource::*]", "Vahr/Loose/DefaultPolicy/Resource"),
        ("AwsSolutions-IAM5[Action::iot:*]", "Vahr/Loose/DefaultPolicy/Resource"),
    }
    # And the app's own findings are acknowledged one by one, each with its reason
    accepted = {
        (v["ruleName"], c["constructPath"]): v["reason"]
        for v in report["suppressedViolations"]
        for c in v["violatingConstructs"]
    }
    assert set(accepted) == {
        ("AwsSolutions-IAM4[Policy::arn:<AWS::Partition>:iam::aws:policy/service-role/"
         "AWSLambdaBasicExecutionRole]", "Vahr/AWS679f53fac002430cb0da5b7982bd2287/ServiceRole/Resource"),
        ("AwsSolutions-IAM5[Resource::*]", "Vahr/DataEndpoint/Lookup/CustomResourcePolicy/Resource"),
        ("AwsSolutions-L1", "Vahr/Skill/Function/Resource"),
        ("AwsSolutions-IAM4[Policy::arn:<AWS::Partition>:iam::aws:policy/service-role/"
         "AWSIoTDeviceDefenderAudit]", "Vahr/DeviceAudit/Role/Resource"),
    }  # fmt: skip
    assert all(len(reason) > 60 for reason in accepted.values())


def test_skill_without_a_package_is_refused_in_one_line(tmp_path: Path) -> None:
    with pytest.raises(
        VahrError, match=r"^skill=true needs .*skill\.json \(run `make skill-model`"
    ):
        synth_app(tmp_path, skill="true", skillPackageDir=str(tmp_path / "missing"))


def test_an_unreadable_fleet_file_is_refused_in_one_line(tmp_path: Path) -> None:
    broken = tmp_path / "fleet.yaml"
    broken.write_text("robots: []\nzones: []\n")
    with pytest.raises(VahrError) as raised:
        build_app(cdk.App(context=cdk_context(fleetFile=str(broken)), outdir=str(tmp_path)))
    assert str(raised.value).startswith(f"{broken}: ")
    assert "\n" not in str(raised.value)
    with pytest.raises(VahrError, match="cannot read"):
        build_app(cdk.App(context=cdk_context(fleetFile=str(tmp_path / "none.yaml"))))
