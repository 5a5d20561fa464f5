"""The announcer: topic rules on the robots' events and presence, feeding the announcer
function (`announcer.app.lambda_handler`, its own code root `lambda/announcer` in the
skill's bundle), which tells the person through Alexa's Proactive Events API what the
announcement policy finds worth telling.

An EventBridge schedule invokes it once a minute as well, so what the policy's rate limit
held back is told within a minute of its turn even when no robot says anything more.

Each announcement Alexa accepted is also published on `vahr/assistant/announcements`, so an
operator station on AWS hears it as it does on the local stack.

Least privilege: the function may read one secret (the skill's Alexa Skill Messaging
client id and secret, created by you, never in the template), read and write its one
state table, publish on the one announcements topic, write its own logs and send to its
dead-letter queue. IoT may invoke it only
from these two rules, EventBridge only from its schedule; with the dispatcher, the
dispatcher's role may invoke it too, to tell a task the fleet lost. A message the rule cannot
deliver (the function throttled or missing) and an event the function failed on after
Lambda's two retries both land in the same encrypted queue, kept 14 days: nothing is lost
silently.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_dynamodb as dynamodb
from aws_cdk import aws_events as events
from aws_cdk import aws_events_targets as targets
from aws_cdk import aws_iam as iam
from aws_cdk import aws_iot as iot
from aws_cdk import aws_lambda as lambda_
from aws_cdk import aws_sqs as sqs
from constructs import Construct

from infra.constructs.python_function import python_function
from infra.constructs.topic_rule import lambda_topic_rule, rule_role
from vahr.protocol import topics

if TYPE_CHECKING:
    from infra.config import InfraConfig

HANDLER = "announcer.app.lambda_handler"
TIMEOUT = cdk.Duration.seconds(30)
MEMORY_MB = 256
# The events that open or clear a fault; progress reports (most of the traffic) are left
# out by the rule, so they cost no invocation.
ANNOUNCED_EVENTS = ("stuck", "failed", "accepted", "stopped", "arrived", "done")
# How often the schedule wakes the function: what the rate limit held back waits at most
# this long past its turn. A tick that finds nothing to tell reads the state and writes
# nothing (43,200 invocations and reads in 30 days, under three cents:
# `infra.cost_estimate.announcer_ticks_cost`).
TICK = cdk.Duration.minutes(1)


def events_sql() -> str:
    which = " OR ".join(f"event = '{name}'" for name in ANNOUNCED_EVENTS)
    return f"SELECT *, topic(3) AS sender FROM '{topics.ALL_EVENTS}' WHERE {which}"


def presence_sql() -> str:
    return (
        "SELECT online, at, topic(3) AS sender "
        f"FROM '{topics.ALL_PRESENCE}' WHERE isBoolean(online)"
    )


class Announcer(Construct):
    """Two rules, the function and its role, its state table and its dead-letter queue."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        config: InfraConfig,
        code: lambda_.Code,
        events_url: str,
        data_endpoint: str,
    ) -> None:
        """`data_endpoint` is the account's iot:Data-ATS host, where announcements are
        published for the operator station."""
        super().__init__(scope, construct_id)
        stack = cdk.Stack.of(self)
        self.table = dynamodb.Table(
            self,
            "State",
            partition_key=dynamodb.Attribute(name="id", type=dynamodb.AttributeType.STRING),
            billing_mode=dynamodb.BillingMode.PAY_PER_REQUEST,
            point_in_time_recovery_specification=dynamodb.PointInTimeRecoverySpecification(
                point_in_time_recovery_enabled=True
            ),
            removal_policy=cdk.RemovalPolicy.DESTROY,
        )
        self.dead_letters = sqs.Queue(
            self,
            "DeadLetters",
            encryption=sqs.QueueEncryption.SQS_MANAGED,
            enforce_ssl=True,
            retention_period=cdk.Duration.days(14),
        )
        self.role = iam.Role(
            self,
            "Role",
            assumed_by=iam.ServicePrincipal("lambda.amazonaws.com"),
            description=(
                "VAHR announcer: its secret, its state, its topic, its logs, its dead letters"
            ),
        )
        # `from_secret_name_v2` ends the ARN in `-??????`, Secrets Manager's random suffix.
        self.secret_arn = stack.format_arn(
            service="secretsmanager",
            resource="secret",
            resource_name=f"{config.announcer_secret_name}-??????",
            arn_format=cdk.ArnFormat.COLON_RESOURCE_NAME,
        )
        self.role.add_to_policy(
            iam.PolicyStatement(
                sid="ReadSkillMessagingSecret",
                actions=["secretsmanager:GetSecretValue"],
                resources=[self.secret_arn],
            )
        )
        self.role.add_to_policy(
            iam.PolicyStatement(
                sid="KeepPolicyState",
                actions=["dynamodb:GetItem", "dynamodb:PutItem"],
                resources=[self.table.table_arn],
            )
        )
        self.topic_arn = stack.format_arn(
            service="iot", resource="topic", resource_name=topics.ASSISTANT_ANNOUNCEMENTS
        )
        self.role.add_to_policy(
            iam.PolicyStatement(
                sid="PublishAnnouncements", actions=["iot:Publish"], resources=[self.topic_arn]
            )
        )
        self.function, self.log_group = python_function(
            self,
            config=config,
            code=code,
            handler=HANDLER,
            description="VAHR announcer: robots' troubles to Alexa notifications",
            role=self.role,
            memory_mb=MEMORY_MB,
            timeout=TIMEOUT,
            dead_letter_queue=self.dead_letters,
            retry_attempts=2,
            max_event_age=cdk.Duration.hours(1),
            environment={
                "VAHR_ANNOUNCER_SECRET": config.announcer_secret_name,
                "VAHR_ANNOUNCER_TABLE": self.table.table_name,
                "VAHR_PROACTIVE_EVENTS_URL": events_url,
                "VAHR_IOT_DATA_ENDPOINT": f"https://{data_endpoint}",
                "VAHR_ANNOUNCE_SETTINGS": config.announce_settings,
                "VAHR_LOG_LEVEL": config.log_level,
            },
        )
        names = {
            "Events": f"{config.announcer_rule_prefix}_events",
            "Presence": f"{config.announcer_rule_prefix}_presence",
        }
        self.rule_role = rule_role(
            self,
            "RuleRole",
            rule_names=list(names.values()),
            description="Lets the VAHR announcer rules dead-letter what they cannot deliver",
        )
        self.dead_letters.grant_send_messages(self.rule_role)
        self.rules = [
            self._rule("Events", names["Events"], events_sql()),
            self._rule("Presence", names["Presence"], presence_sql()),
        ]
        # A tick EventBridge cannot deliver is not retried: the next one, a minute later,
        # does the same work (and the held announcements stay in the state meanwhile).
        self.schedule = events.Rule(
            self,
            "Tick",
            description="Wakes the VAHR announcer to tell what its rate limit held back",
            schedule=events.Schedule.rate(TICK),
            targets=[targets.LambdaFunction(self.function, retry_attempts=0, max_event_age=TICK)],
        )

    def _rule(self, construct_id: str, name: str, sql: str) -> iot.CfnTopicRule:
        rule = lambda_topic_rule(
            self,
            construct_id,
            name=name,
            sql=sql,
            description="Robot events and presence -> the VAHR announcer",
            function=self.function,
            dead_letters=self.dead_letters,
            role=self.rule_role,
        )
        self.function.add_permission(
            f"{construct_id}RuleInvoke",
            principal=iam.ServicePrincipal("iot.amazonaws.com"),
            action="lambda:InvokeFunction",
            source_arn=rule.attr_arn,
            source_account=cdk.Stack.of(self).account,
        )
        return rule
