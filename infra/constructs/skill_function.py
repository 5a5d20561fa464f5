"""The skill's Lambda function: code built by `infra.lambda_asset`, least-privilege IoT rights.

The function may publish only to the robots' command topics and the fleet topic, read only
the fleet's shadows, and read and update only the experiment thing's shadow. It logs to its
own log group with a retention period.

Which Alexa skill may invoke it, and which the handler serves (skill.skill_gate), is one
of three, decided at synth (infra.config refuses a stack that says none of them):

- a skill id given (`-c skillId=`, or `.ask/ask-states.json` after `ask deploy`): the
  permission carries it as `EventSourceToken` and the handler gets it as `VAHR_SKILL_ID`;
- the skill created by the stack (`-c skill=true`): its id exists only once the skill
  does, so `AlexaSkill` grants the permission and writes the id into an SSM parameter,
  which the handler reads (`VAHR_SKILL_ID_PARAMETER`);
- `-c allowAnySkill=true`: any skill may invoke it and the handler serves any
  (`VAHR_ALLOW_ANY_SKILL`), a risk the user took by name.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
import jsii
from aws_cdk import aws_iam as iam
from aws_cdk import aws_lambda as lambda_
from constructs import Construct

from infra import lambda_asset
from infra.constructs.python_function import python_function
from vahr.protocol import topics

if TYPE_CHECKING:
    from infra.config import InfraConfig
    from vahr.domain import Fleet

HANDLER = "skill.app.lambda_handler"
# Alexa gives a skill 8 s per answer; the handler bounds its own waits well inside that.
TIMEOUT = cdk.Duration.seconds(8)
MEMORY_MB = 512


@jsii.implements(cdk.ILocalBundling)
class LocalBundler:
    """Runs `infra.lambda_asset.build` on this machine, so synth needs no Docker."""

    def __init__(
        self, *, architecture: str, fleet_file: Path, compile_with: Path | None = None
    ) -> None:
        self._architecture = architecture
        self._fleet_file = fleet_file
        self._compile_with = compile_with

    def try_bundle(self, output_dir: str, options: Any = None, **_: Any) -> bool:
        # jsii passes the bundling options positionally; the build needs none of them.
        lambda_asset.build(
            Path(output_dir),
            architecture=self._architecture,
            fleet_file=self._fleet_file,
            compile_with=self._compile_with,
        )
        return True


def skill_code(config: InfraConfig) -> lambda_.Code:
    """The function's code asset, hashed over everything the build puts into it."""
    return lambda_.Code.from_asset(
        str(lambda_asset.REPO_ROOT / lambda_asset.SKILL_DIR),
        asset_hash_type=cdk.AssetHashType.CUSTOM,
        asset_hash=lambda_asset.source_hash(
            architecture=config.architecture,
            fleet_file=config.fleet_file,
            precompiled=config.lambda_python is not None,
        ),
        bundling=cdk.BundlingOptions(
            # Never pulled: local bundling always succeeds or raises.
            image=lambda_.Runtime.PYTHON_3_12.bundling_image,
            local=LocalBundler(
                architecture=config.architecture,
                fleet_file=config.fleet_file,
                compile_with=config.lambda_python,
            ),
        ),
    )


class SkillFunction(Construct):
    """The Alexa skill handler (`skill.app.lambda_handler`) and its execution role."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        config: InfraConfig,
        fleet: Fleet,
        data_endpoint: str,
        code: lambda_.Code | None = None,
    ) -> None:
        super().__init__(scope, construct_id)
        stack = cdk.Stack.of(self)
        self.role = iam.Role(
            self,
            "Role",
            assumed_by=iam.ServicePrincipal("lambda.amazonaws.com"),
            description="VAHR skill handler: robot commands out, shadows in, nothing else",
        )
        for statement in skill_statements(stack, fleet):
            self.role.add_to_policy(statement)
        environment = {
            "VAHR_IOT_DATA_ENDPOINT": f"https://{data_endpoint}",
            "VAHR_ACK_TIMEOUT_S": f"{config.ack_timeout_s:g}",
            "VAHR_LOG_LEVEL": config.log_level,
        }
        invocation = config.skill_invocation()
        # The parameter a stack-made skill's id is written to (None: the id is known here).
        self.skill_id_parameter = (
            skill_id_parameter_name(stack.stack_name) if invocation == "stack_skill" else None
        )
        if config.skill_id:
            environment["VAHR_SKILL_ID"] = config.skill_id
        elif self.skill_id_parameter is not None:
            environment["VAHR_SKILL_ID_PARAMETER"] = self.skill_id_parameter
            self.role.add_to_policy(
                iam.PolicyStatement(
                    sid="ReadTheSkillId",
                    actions=["ssm:GetParameter"],
                    resources=[
                        stack.format_arn(
                            service="ssm",
                            resource="parameter",
                            resource_name=self.skill_id_parameter.lstrip("/"),
                        )
                    ],
                )
            )
        elif config.allow_any_skill:
            environment["VAHR_ALLOW_ANY_SKILL"] = "true"
        self.function, self.log_group = python_function(
            self,
            config=config,
            code=code or skill_code(config),
            handler=HANDLER,
            description="VAHR Alexa skill: voice commands to the robot fleet over AWS IoT",
            role=self.role,
            memory_mb=MEMORY_MB,
            timeout=TIMEOUT,
            environment=environment,
        )
        if self.skill_id_parameter is not None:
            return  # AlexaSkill grants Alexa's invocation, once the skill's id exists
        if not config.skill_id:
            cdk.Annotations.of(self.function).add_warning_v2(
                "vahr:any-skill-allowed",
                "allowAnySkill=true: any Alexa skill may invoke this function and the handler "
                "serves it. Deploy again with the skill's id (-c skillId=..., or after `ask "
                "deploy`, from .ask/ask-states.json) to close it.",
            )
        self.function.add_permission(
            "AlexaInvoke",
            principal=iam.ServicePrincipal("alexa-appkit.amazon.com"),
            action="lambda:InvokeFunction",
            event_source_token=config.skill_id,
        )


def skill_id_parameter_name(stack_name: str) -> str:
    """The SSM parameter a stack-made skill's id is kept in."""
    return f"/vahr/{stack_name}/skill-id"


def skill_statements(stack: cdk.Stack, fleet: Fleet) -> list[iam.PolicyStatement]:
    """The IoT rights of the skill, exactly: publish commands, read shadows, experiment."""

    def arn(resource: str, name: str) -> str:
        return stack.format_arn(service="iot", resource=resource, resource_name=name)

    robots = fleet.robot_things
    return [
        iam.PolicyStatement(
            sid="PublishCommands",
            actions=["iot:Publish"],
            resources=[arn("topic", topics.robot_cmd(thing)) for thing in robots]
            + [arn("topic", topics.FLEET_CMD)],
        ),
        iam.PolicyStatement(
            sid="ReadRobotShadows",
            actions=["iot:GetThingShadow"],
            resources=[arn("thing", thing) for thing in robots],
        ),
        iam.PolicyStatement(
            sid="ReadWriteExperimentShadow",
            actions=["iot:GetThingShadow", "iot:UpdateThingShadow"],
            resources=[arn("thing", fleet.experiment_thing)],
        ),
    ]
