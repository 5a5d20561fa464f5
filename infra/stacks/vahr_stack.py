"""The VAHR stack: composes the constructs, adds outputs and tags. No resource logic here."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
from aws_cdk import aws_logs as logs

from announcer.config import events_url
from infra.constructs.alarms import Alarms
from infra.constructs.alexa_skill import AlexaSkill
from infra.constructs.announcer import Announcer
from infra.constructs.device_audit import DeviceAudit
from infra.constructs.dispatcher import Dispatcher
from infra.constructs.fleet_indexing import FleetIndexing
from infra.constructs.iot_endpoint import IotEndpoint
from infra.constructs.iot_fleet import IotFleet
from infra.constructs.iot_logging import IotLogging
from infra.constructs.operator_policy import OperatorPolicy
from infra.constructs.people_tables import PeopleTables
from infra.constructs.presence_rule import PresenceRule
from infra.constructs.robot_policy import RobotPolicy
from infra.constructs.skill_function import SkillFunction
from infra.constructs.skill_function import skill_code as bundled_code
from infra.constructs.task_table import TaskTable
from infra.constructs.weather_bot import WeatherBot

if TYPE_CHECKING:
    from aws_cdk import aws_lambda as lambda_
    from constructs import Construct

    from infra.config import InfraConfig
    from vahr.domain import Fleet


class VahrStack(cdk.Stack):
    """IoT fleet, robot, station and recorder policies, presence rule, skill function, IoT
    logging, the Device Defender audit and the alarms; optionally the Alexa skill, the Lex
    bot, the announcer and the fleet dispatcher."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        config: InfraConfig,
        fleet: Fleet,
        skill_code: lambda_.Code | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(scope, construct_id, **kwargs)
        # The deploy-time lookups share one provider function; its logs expire too.
        provider_logs = logs.LogGroup(
            self,
            "ProviderLogs",
            retention=logs.RetentionDays.ONE_WEEK,
            removal_policy=cdk.RemovalPolicy.DESTROY,
        )
        self.fleet = IotFleet(
            self,
            "Fleet",
            fleet=fleet,
            group_name=config.thing_group_name,
            provider_logs=provider_logs,
        )
        self.weather_bot = (
            WeatherBot(
                self,
                "WeatherBot",
                answers_file=config.weather_answers_file,
                bot_name=config.bot_name,
                alias_name=config.bot_alias_name,
                role_alias_name=config.role_alias_name,
            )
            if config.lex
            else None
        )
        self.robot_policy = RobotPolicy(
            self,
            "RobotPolicy",
            policy_name=config.robot_policy_name,
            role_alias_arn=self.weather_bot.role_alias_arn if self.weather_bot else None,
        )
        self.station_policy = OperatorPolicy(
            self,
            "StationPolicy",
            operator="station",
            policy_name=config.station_policy_name,
            things=fleet.robot_things,
        )
        self.recorder_policy = OperatorPolicy(
            self,
            "RecorderPolicy",
            operator="recorder",
            policy_name=config.recorder_policy_name,
            things=fleet.robot_things,
        )
        self.presence = PresenceRule(
            self, "Presence", rule_name=config.presence_rule_name, things=fleet.robot_things
        )
        self.data_endpoint = IotEndpoint(
            self, "DataEndpoint", endpoint_type="iot:Data-ATS", provider_logs=provider_logs
        )
        # One bundle holds every function's code root (infra/lambda_asset.py): built once.
        code = skill_code or bundled_code(config)
        self.skill_function = SkillFunction(
            self,
            "Skill",
            config=config,
            fleet=fleet,
            data_endpoint=self.data_endpoint.address,
            code=code,
        )
        # Who may do what, and the trail of what was done (infra/constructs/people_tables.py).
        self.people = PeopleTables(
            self,
            "People",
            people=config.people,
            audit_deletion_protection=config.audit_table_deletion_protection,
        )
        skill = self.skill_function.function
        skill.add_environment("VAHR_AUDIT_TABLE", self.people.audit.table_name)
        self.people.admit_trail_writer(self.skill_function.role)
        if self.people.users is not None:
            skill.add_environment("VAHR_USERS_TABLE", self.people.users.table_name)
            self.people.admit_reader_of_people(self.skill_function.role)
        self.announcer = (
            Announcer(
                self,
                "Announcer",
                config=config,
                code=code,
                events_url=events_url(config.alexa_region, config.announcer_stage),
                data_endpoint=self.data_endpoint.address,
            )
            if config.announcer
            else None
        )
        self.fleet_indexing: FleetIndexing | None = None
        self.task_table: TaskTable | None = None
        self.dispatcher: Dispatcher | None = None
        if config.dispatcher:
            self.fleet_indexing = FleetIndexing(self, "FleetIndexing", provider_logs=provider_logs)
            self.task_table = TaskTable(
                self, "Tasks", deletion_protection=config.task_table_deletion_protection
            )
            self.dispatcher = Dispatcher(
                self,
                "Dispatcher",
                config=config,
                fleet=fleet,
                code=code,
                table=self.task_table.table,
                index_arn=self.fleet_indexing.index_arn,
                data_endpoint=self.data_endpoint.address,
                announcer=self.announcer.function if self.announcer is not None else None,
            )
            self.dispatcher.admit_skill(self.skill_function.function, self.skill_function.role)
            # What the dispatcher does by itself (a queued task given to a freed robot).
            self.dispatcher.function.add_environment(
                "VAHR_AUDIT_TABLE", self.people.audit.table_name
            )
            self.people.admit_trail_writer(self.dispatcher.role)
        self.credentials_endpoint = (
            IotEndpoint(
                self,
                "CredentialProvider",
                endpoint_type="iot:CredentialProvider",
                provider_logs=provider_logs,
            )
            if config.lex
            else None
        )
        self.alexa_skill = (
            AlexaSkill(
                self,
                "AlexaSkill",
                package_dir=config.skill_package_dir,
                function=self.skill_function.function,
                lwa_secret_name=config.lwa_secret_name,
                vendor_id=config.vendor_id,
                skill_id_parameter=self.skill_function.skill_id_parameter,
                provider_logs=provider_logs,
            )
            if config.skill
            else None
        )
        self.iot_logging = (
            IotLogging(self, "IotLogging", config=config) if config.iot_logging else None
        )
        self.alarms = Alarms(self, "Alarms", email=config.alarm_email)
        self.alarms.watch_function("Skill", self.skill_function.function)
        if self.announcer is not None:
            self.alarms.watch_function("Announcer", self.announcer.function)
            self.alarms.watch_queue("Announcer", self.announcer.dead_letters)
        if self.dispatcher is not None:
            self.alarms.watch_function("Dispatcher", self.dispatcher.function)
            self.alarms.watch_queue("Dispatcher", self.dispatcher.dead_letters)
        self.device_audit = (
            DeviceAudit(
                self,
                "DeviceAudit",
                audit_name=f"{config.stack_name.lower()}-daily-audit",
                findings=self.alarms.topic,
                findings_key=self.alarms.key,
            )
            if config.device_audit
            else None
        )
        self._outputs(config)
        self._acknowledge_findings(config)
        cdk.Tags.of(self).add("project", "vahr")

    def _acknowledge_findings(self, config: InfraConfig) -> None:
        """The cdk-nag findings this stack accepts, each for a stated reason."""

        def acknowledge(scope: Construct, finding: str, reason: str) -> None:
            cdk.Validations.of(scope).acknowledge(
                cdk.Acknowledgment(id=f"AwsSolutions::AwsSolutions-{finding}", reason=reason)
            )

        # The provider function that CDK's AwsCustomResource shares across the stack.
        acknowledge(
            self,
            "IAM4[Policy::arn:<AWS::Partition>:iam::aws:policy/service-role/"
            "AWSLambdaBasicExecutionRole]",
            "Only the CDK custom-resource provider (endpoint lookups, thing-group membership) "
            "uses it; it grants writing that function's own CloudWatch logs and nothing else.",
        )
        for lookup in (self.data_endpoint, self.credentials_endpoint):
            if lookup is not None:
                acknowledge(
                    lookup,
                    "IAM5[Resource::*]",
                    "iot:DescribeEndpoint has no resource type in IAM, so its only valid "
                    "resource is '*'; the statement allows that one read-only action.",
                )
        if self.announcer is not None:
            acknowledge(
                self.announcer.function,
                "L1",
                "Pinned to python3.12 with the skill function: it runs from the same bundle, "
                "whose compiled wheels are cross-built for cp312.",
            )
            acknowledge(
                self.announcer.role,
                f"IAM5[Resource::arn:<AWS::Partition>:secretsmanager:<AWS::Region>:"
                f"<AWS::AccountId>:secret:{config.announcer_secret_name}-??????]",
                "The one secret the announcer reads, named by you; '-??????' stands only for "
                "the six random characters Secrets Manager appends to every secret's ARN.",
            )
            acknowledge(
                self.announcer.dead_letters,
                "SQS3",
                "This queue is itself the dead-letter queue of the announcer function and its "
                "rules' error action; a dead-letter queue of its own would hold nothing.",
            )
        if self.dispatcher is not None and self.fleet_indexing is not None:
            acknowledge(
                self.dispatcher.function,
                "L1",
                "Pinned to python3.12 with the skill function: it runs from the same bundle, "
                "whose compiled wheels are cross-built for cp312.",
            )
            acknowledge(
                self.dispatcher.dead_letters,
                "SQS3",
                "This queue is itself the dead-letter queue of the dispatcher function and its "
                "rule's error action; a dead-letter queue of its own would hold nothing.",
            )
            acknowledge(
                self.fleet_indexing,
                "IAM5[Resource::*]",
                "iot:UpdateIndexingConfiguration has no resource type in IAM (the indexing "
                "configuration is the account's), so its only valid resource is '*'; the "
                "statement allows that one action.",
            )
        if self.device_audit is not None:
            acknowledge(
                self.device_audit.role,
                "IAM4[Policy::arn:<AWS::Partition>:iam::aws:policy/service-role/"
                "AWSIoTDeviceDefenderAudit]",
                "AWS's own policy for Device Defender's audit role: read-only describe and "
                "list rights over the IoT configuration the checks read, kept by AWS as checks "
                "change; only iot.amazonaws.com may assume the role, for this account.",
            )
        acknowledge(
            self.skill_function,
            "L1",
            "Pinned to python3.12 on purpose: the bundle's compiled wheels (msgspec, PyYAML) "
            "are cross-built for cp312 and the handler is tested on 3.12; moving runtimes "
            "is a deliberate change made together with infra/lambda_asset.py.",
        )

    def _outputs(self, config: InfraConfig) -> None:
        def output(name: str, value: str, description: str) -> None:
            cdk.CfnOutput(self, name, value=value, description=description)

        output(
            "IotDataEndpoint",
            self.data_endpoint.address,
            "AWS IoT data endpoint (ATS): robot-agent run --endpoint",
        )
        output(
            "SkillFunctionArn",
            self.skill_function.function.function_arn,
            "Skill endpoint: python -m infra.skill_endpoint writes it into skill.json",
        )
        output("ThingNames", ",".join(self.fleet.thing_names), "The robots' thing names")
        output("ExperimentThing", self.fleet.experiment_thing_name, "The experiment's thing")
        output("RobotPolicyName", config.robot_policy_name, "IoT policy for robot certificates")
        output(
            "StationPolicyName",
            config.station_policy_name,
            "IoT policy for the operator station's certificate (client ids vahr-station-*)",
        )
        output(
            "RecorderPolicyName",
            config.recorder_policy_name,
            "IoT policy for the experiment recorder's certificate (client ids vahr-experiment-*)",
        )
        output("AlarmTopicArn", self.alarms.topic.topic_arn, "Subscribe here to hear of trouble")
        output(
            "AuditTableName",
            self.people.audit.table_name,
            "The audit trail of every command: vahr audit --table NAME [--verify]",
        )
        if self.people.users is not None:
            output(
                "UsersTableName",
                self.people.users.table_name,
                "Who may do what: vahr users import FILE --table NAME",
            )
        if self.weather_bot is not None and self.credentials_endpoint is not None:
            output(
                "CredentialsEndpoint",
                self.credentials_endpoint.address,
                "AWS IoT credentials provider endpoint for the role alias",
            )
            output("RoleAlias", self.weather_bot.role_alias_name, "IoT role alias for Lex")
            output("BotId", self.weather_bot.bot_id, "Lex V2 bot id (weather answers)")
            output("BotAliasId", self.weather_bot.alias_id, "Lex V2 bot alias id")
        if self.dispatcher is not None and self.task_table is not None:
            output(
                "DispatcherFunctionName",
                self.dispatcher.function.function_name,
                "The fleet dispatcher (the skill's VAHR_DISPATCHER_FUNCTION)",
            )
            output("TaskTableName", self.task_table.table.table_name, "The fleet's task queue")
        if self.alexa_skill is not None:
            output("SkillId", self.alexa_skill.skill_id, "The Alexa skill id (set -c skillId=)")
