"""The fleet dispatcher on AWS: the dispatcher function (`dispatcher.app.lambda_handler`,
its own code root `lambda/dispatcher` in the skill's bundle), the topic rule that tells it
when a robot became free, and what the skill needs to reach it.

The rule reads every classic shadow's `update/documents` and passes on only the updates
that leave a robot idle or stopped when it was not, or that change whether it is
connected while it is free (`freed_sql`); driving, progress and pose reports cost a rule
evaluation and nothing more. The skill invokes the function synchronously to submit,
list and cancel tasks. An EventBridge schedule wakes it once a minute to offer again the
commands robots never acknowledged and to give queued tasks to robots that are free now,
should a rule event have been lost. With the announcer, it may invoke the announcer
function (asynchronously) to tell a task it lost.

Least privilege: the function may read and write only its task table, search only the
`AWS_Things` index, publish only on the fleet's robots' command topics, write its own
logs, send to its dead-letter queue and invoke the announcer function (when there is one).
IoT may invoke it only from its rule, EventBridge
only from its schedule. A message
the rule cannot deliver and an event the function failed on after Lambda's two retries
land in one encrypted queue, kept 14 days.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_events as events
from aws_cdk import aws_events_targets as targets
from aws_cdk import aws_iam as iam
from aws_cdk import aws_sqs as sqs
from constructs import Construct

from infra.constructs.fleet_indexing import INDEX_NAME
from infra.constructs.python_function import python_function
from infra.constructs.topic_rule import lambda_topic_rule, rule_role
from vahr.dispatch import IDLE_STATUSES
from vahr.protocol import topics

if TYPE_CHECKING:
    from aws_cdk import aws_dynamodb as dynamodb
    from aws_cdk import aws_lambda as lambda_

    from infra.config import InfraConfig
    from vahr.domain import Fleet

HANDLER = "dispatcher.app.lambda_handler"
# A rule's event waits for nothing but AWS calls; a submit over 10,000 free robots reads
# 100 pages of the index. The skill bounds its own wait well inside Alexa's 8 s.
TIMEOUT = cdk.Duration.seconds(30)
MEMORY_MB = 512
# The fleet index the skill may ask for counts and searches (issue 35's status summary).
SKILL_INDEX_ACTIONS = ("iot:SearchIndex", "iot:GetBucketsAggregation", "iot:GetStatistics")
# How often the schedule has the function offer again the commands robots never acknowledged
# and give queued tasks to robots free now, in case a robot's rule event was lost. With no
# open task a tick is one read of the open tasks (and the closed zones told again).
TICK = cdk.Duration.minutes(1)


def freed_sql() -> str:
    """The rule query: a robot's whole reported state, when it became free.

    AWS IoT SQL gives Undefined, not false, for a comparison with a missing field, and
    Undefined in AND or OR makes the whole WHERE Undefined (not selected). A shadow's first
    document has no `previous`, so the CASE answers true for it instead of comparing.
    """
    now, before = "current.state.reported", "previous.state.reported"
    free = " OR ".join(f"{now}.status = '{status}'" for status in sorted(IDLE_STATUSES))
    changed = f"{before}.status <> {now}.status OR {before}.connected <> {now}.connected"
    return (
        f"SELECT topic(3) AS thing, {now} AS reported "
        f"FROM '{topics.ALL_SHADOW_DOCUMENTS}' "
        f"WHERE ({free}) AND CASE isUndefined({before}.status) WHEN true THEN true "
        f"ELSE {changed} END"
    )


class Dispatcher(Construct):
    """The function and its role, its rule and the rule's role, its dead-letter queue."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        config: InfraConfig,
        fleet: Fleet,
        code: lambda_.Code,
        table: dynamodb.ITable,
        index_arn: str,
        data_endpoint: str,
        announcer: lambda_.IFunction | None = None,
    ) -> None:
        """`announcer`: the announcer function, told of each task the dispatcher loses."""
        super().__init__(scope, construct_id)
        stack = cdk.Stack.of(self)
        self.index_arn = index_arn
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
            description="VAHR dispatcher: its task table, the fleet index, robot commands",
        )
        self.role.add_to_policy(
            iam.PolicyStatement(
                sid="KeepTasks",
                # A transaction's writes are authorized as the PutItem and DeleteItem in it.
                actions=[
                    "dynamodb:GetItem",
                    "dynamodb:PutItem",
                    "dynamodb:DeleteItem",
                    "dynamodb:UpdateItem",
                    "dynamodb:Query",
                ],
                resources=[table.table_arn],
            )
        )
        self.role.add_to_policy(
            iam.PolicyStatement(
                sid="FindRobots", actions=["iot:SearchIndex"], resources=[index_arn]
            )
        )
        self.role.add_to_policy(
            iam.PolicyStatement(
                sid="CommandRobots",
                actions=["iot:Publish"],
                resources=[
                    stack.format_arn(
                        service="iot", resource="topic", resource_name=topics.robot_cmd(thing)
                    )
                    for thing in fleet.robot_things
                ],
            )
        )
        closures = stack.format_arn(
            service="iot", resource="topic", resource_name=topics.FLEET_ZONES
        )
        self.role.add_to_policy(
            iam.PolicyStatement(
                # The zones closed now, retained for robots that connect later.
                sid="TellRobotsClosedZones",
                actions=["iot:Publish", "iot:RetainPublish"],
                resources=[closures],
            )
        )
        environment = {
            "VAHR_TASK_TABLE": table.table_name,
            "VAHR_FLEET_INDEX": INDEX_NAME,
            "VAHR_IOT_DATA_ENDPOINT": f"https://{data_endpoint}",
            "VAHR_LOG_LEVEL": config.log_level,
        }
        if announcer is not None:
            self.role.add_to_policy(
                iam.PolicyStatement(
                    # A lost task told; the function's ARN alone (no versions, no aliases).
                    sid="TellLostTasks",
                    actions=["lambda:InvokeFunction"],
                    resources=[announcer.function_arn],
                )
            )
            environment["VAHR_ANNOUNCER_FUNCTION"] = announcer.function_name
        self.function, self.log_group = python_function(
            self,
            config=config,
            code=code,
            handler=HANDLER,
            description="VAHR dispatcher: fleet tasks to the best free robot",
            role=self.role,
            memory_mb=MEMORY_MB,
            timeout=TIMEOUT,
            dead_letter_queue=self.dead_letters,
            retry_attempts=2,
            max_event_age=cdk.Duration.hours(1),
            environment=environment,
        )
        self.rule_role = rule_role(
            self,
            "RuleRole",
            rule_names=[config.dispatcher_rule_name],
            description="Lets the VAHR dispatcher rule dead-letter what it cannot deliver",
        )
        self.dead_letters.grant_send_messages(self.rule_role)
        self.rule = lambda_topic_rule(
            self,
            "RobotFreed",
            name=config.dispatcher_rule_name,
            sql=freed_sql(),
            description="A robot became free -> the VAHR dispatcher gives it the next task",
            function=self.function,
            dead_letters=self.dead_letters,
            role=self.rule_role,
        )
        # A tick EventBridge cannot deliver is not retried: the next one does the same work.
        self.schedule = events.Rule(
            self,
            "Tick",
            description="Wakes the VAHR dispatcher to offer unacknowledged and queued tasks",
            schedule=events.Schedule.rate(TICK),
            targets=[targets.LambdaFunction(self.function, retry_attempts=0, max_event_age=TICK)],
        )
        self.function.add_permission(
            "RuleInvoke",
            principal=iam.ServicePrincipal("iot.amazonaws.com"),
            action="lambda:InvokeFunction",
            source_arn=self.rule.attr_arn,
            source_account=stack.account,
        )

    def admit_skill(self, skill: lambda_.Function, role: iam.IRole) -> None:
        """Let the skill invoke the dispatcher and ask the fleet index for counts and
        searches, and tell it where both are."""
        role.add_to_principal_policy(
            iam.PolicyStatement(
                sid="InvokeDispatcher",
                actions=["lambda:InvokeFunction"],
                resources=[self.function.function_arn],
            )
        )
        role.add_to_principal_policy(
            iam.PolicyStatement(
                sid="AskFleetIndex", actions=list(SKILL_INDEX_ACTIONS), resources=[self.index_arn]
            )
        )
        skill.add_environment("VAHR_DISPATCHER_FUNCTION", self.function.function_name)
        skill.add_environment("VAHR_FLEET_INDEX", INDEX_NAME)
