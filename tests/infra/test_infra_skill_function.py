"""The skill's Lambda function: runtime, configuration, and exactly its IAM rights."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk.assertions import Annotations, Match, Template
from template_tools import SKILL_ID, bare_stack, only, resources, role_grants

from infra.config import InfraConfig
from infra.constructs.skill_function import SkillFunction
from vahr.errors import VahrError

if TYPE_CHECKING:
    from vahr.domain import Fleet

PREFIX = "arn:aws:iot:us-east-1:123456789012"
DATA_HOST = "a1b2c3d4e5f6g7-ats.iot.us-east-1.amazonaws.com"


def synth(outdir: Path, fleet: Fleet, config: InfraConfig) -> dict[str, Any]:
    stack = bare_stack(outdir)
    SkillFunction(stack, "Skill", config=config, fleet=fleet, data_endpoint=DATA_HOST)
    return Template.from_stack(stack).to_json()


@pytest.fixture(scope="module")
def template(tmp_path_factory: pytest.TempPathFactory, fleet: Fleet) -> dict[str, Any]:
    # Any skill allowed (by name): the permission and environment of the other ways are
    # tested below.
    return synth(tmp_path_factory.mktemp("skill"), fleet, InfraConfig(allow_any_skill=True))


def test_the_function_runs_the_skill_handler_on_python_3_12(template: dict[str, Any]) -> None:
    function = only(template, "AWS::Lambda::Function")
    assert function["Runtime"] == "python3.12"
    assert function["Handler"] == "skill.app.lambda_handler"
    assert function["Architectures"] == ["x86_64"]
    assert function["Timeout"] <= 8  # Alexa waits 8 s for an answer
    assert function["MemorySize"] == 512


def test_the_function_is_configured_through_the_agreed_environment(
    template: dict[str, Any],
) -> None:
    variables = only(template, "AWS::Lambda::Function")["Environment"]["Variables"]
    assert variables == {
        "VAHR_IOT_DATA_ENDPOINT": f"https://{DATA_HOST}",
        "VAHR_ACK_TIMEOUT_S": "2.5",
        "VAHR_LOG_LEVEL": "INFO",
        "VAHR_ALLOW_ANY_SKILL": "true",
    }


def test_logs_go_to_its_own_group_with_a_retention(template: dict[str, Any]) -> None:
    [(group_id, group)] = resources(template, "AWS::Logs::LogGroup").items()
    assert group["RetentionInDays"] == 30
    assert only(template, "AWS::Lambda::Function")["LoggingConfig"] == {"LogGroup": f"<{group_id}>"}


def test_the_role_has_exactly_the_skill_rights(template: dict[str, Any]) -> None:
    # Given the function's execution role
    function = only(template, "AWS::Lambda::Function")
    role_id = function["Role"].strip("<>").split(".")[0]
    role = resources(template, "AWS::IAM::Role")[role_id]
    # Then it has no managed policies, and its inline rights are exactly these
    assert "ManagedPolicyArns" not in role
    [group_id] = resources(template, "AWS::Logs::LogGroup")
    assert role_grants(template, role_id) == {
        ("Allow", "iot:Publish", f"{PREFIX}:topic/vahr/robots/placebot1/cmd"),
        ("Allow", "iot:Publish", f"{PREFIX}:topic/vahr/robots/placebot2/cmd"),
        ("Allow", "iot:Publish", f"{PREFIX}:topic/vahr/fleet/cmd"),
        ("Allow", "iot:GetThingShadow", f"{PREFIX}:thing/placebot1"),
        ("Allow", "iot:GetThingShadow", f"{PREFIX}:thing/placebot2"),
        ("Allow", "iot:GetThingShadow", f"{PREFIX}:thing/vahr-experiment"),
        ("Allow", "iot:UpdateThingShadow", f"{PREFIX}:thing/vahr-experiment"),
        ("Allow", "logs:CreateLogStream", f"<{group_id}.Arn>"),
        ("Allow", "logs:PutLogEvents", f"<{group_id}.Arn>"),
    }


def test_alexa_may_invoke_it_and_with_any_skill_allowed_any_skill_can(
    template: dict[str, Any],
) -> None:
    permission = only(template, "AWS::Lambda::Permission")
    assert permission["Principal"] == "alexa-appkit.amazon.com"
    assert permission["Action"] == "lambda:InvokeFunction"
    assert "EventSourceToken" not in permission


def test_with_a_skill_id_only_that_skill_may_invoke_and_the_handler_checks_it(
    tmp_path: Path, fleet: Fleet
) -> None:
    # Given a configuration that knows the skill id
    config = InfraConfig(skill_id=SKILL_ID, architecture="arm64", log_level="DEBUG")
    template = synth(tmp_path, fleet, config)
    # Then the invoke permission is conditioned on it and the handler is told it
    assert only(template, "AWS::Lambda::Permission")["EventSourceToken"] == SKILL_ID
    function = only(template, "AWS::Lambda::Function")
    assert function["Environment"]["Variables"]["VAHR_SKILL_ID"] == SKILL_ID
    assert function["Environment"]["Variables"]["VAHR_LOG_LEVEL"] == "DEBUG"
    assert function["Architectures"] == ["arm64"]


def test_a_precompiling_build_is_a_different_asset(tmp_path: Path, fleet: Fleet) -> None:
    # Given the same sources, with and without -c lambdaPython
    plain = only(
        synth(tmp_path / "plain", fleet, InfraConfig(skill_id=SKILL_ID)), "AWS::Lambda::Function"
    )
    compiled = only(
        synth(
            tmp_path / "compiled",
            fleet,
            InfraConfig(skill_id=SKILL_ID, lambda_python=Path(sys.executable)),
        ),
        "AWS::Lambda::Function",
    )
    # Then CDK sees two different code assets, so switching it redeploys the code
    assert plain["Code"]["S3Key"] != compiled["Code"]["S3Key"]


def test_synth_warns_while_the_function_is_open_to_any_skill(tmp_path: Path, fleet: Fleet) -> None:
    def warnings(config: InfraConfig, outdir: Path) -> list[str]:
        stack = bare_stack(outdir)
        SkillFunction(stack, "Skill", config=config, fleet=fleet, data_endpoint=DATA_HOST)
        found = Annotations.from_stack(stack).find_warning("*", Match.any_value())
        return [str(entry.entry.data) for entry in found]

    opened = warnings(InfraConfig(allow_any_skill=True), tmp_path / "a")
    assert any("any Alexa skill may invoke" in w for w in opened)
    locked = warnings(InfraConfig(skill_id=SKILL_ID), tmp_path / "b")
    assert not any("any Alexa skill" in w for w in locked)


def test_a_function_no_skill_may_be_named_for_is_refused(tmp_path: Path, fleet: Fleet) -> None:
    # (infra.config refuses such a context; the construct refuses such a configuration too)
    with pytest.raises(VahrError, match=r"^skillId: none is known, .* -c allowAnySkill=true$"):
        synth(tmp_path, fleet, InfraConfig())


def test_a_skill_the_stack_creates_is_read_from_its_parameter(tmp_path: Path, fleet: Fleet) -> None:
    # Given the skill is created by the stack, its id unknown at synth
    template = synth(tmp_path, fleet, InfraConfig(skill=True))
    # Then the handler is told where to read it, and may read that one parameter
    function = only(template, "AWS::Lambda::Function")
    variables = function["Environment"]["Variables"]
    assert variables["VAHR_SKILL_ID_PARAMETER"] == "/vahr/Bare/skill-id"
    assert "VAHR_SKILL_ID" not in variables and "VAHR_ALLOW_ANY_SKILL" not in variables
    role_id = function["Role"].strip("<>").split(".")[0]
    ssm = {grant for grant in role_grants(template, role_id) if grant[1].startswith("ssm:")}
    assert ssm == {
        (
            "Allow",
            "ssm:GetParameter",
            "arn:aws:ssm:us-east-1:123456789012:parameter/vahr/Bare/skill-id",
        )
    }
    # And this construct grants Alexa nothing: the skill's own construct does, by its id
    assert resources(template, "AWS::Lambda::Permission") == {}
