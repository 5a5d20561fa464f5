"""Alarms on what must not go unnoticed, sent to one SNS topic people subscribe to.

Every dead-letter queue holding a message (an event a function or a rule could not take),
and every function's errors and throttles, in any minute, raise an alarm; the Device
Defender audit's findings go to the same topic. The topic is encrypted with a key of its
own (rotated yearly) that CloudWatch may use, and takes publishes over TLS only. Subscribe
with `-c alarmEmail=you@lab.example` (confirm the mail AWS sends), or later in the console.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_cloudwatch as cloudwatch
from aws_cdk import aws_cloudwatch_actions as actions
from aws_cdk import aws_iam as iam
from aws_cdk import aws_kms as kms
from aws_cdk import aws_sns as sns
from aws_cdk import aws_sns_subscriptions as subscriptions
from constructs import Construct

if TYPE_CHECKING:
    from aws_cdk import aws_lambda as lambda_
    from aws_cdk import aws_sqs as sqs

PERIOD = cdk.Duration.minutes(1)


class Alarms(Construct):
    """The topic, its key, the optional email subscription, and `watch_*` to add alarms."""

    def __init__(self, scope: Construct, construct_id: str, *, email: str | None) -> None:
        super().__init__(scope, construct_id)
        stack = cdk.Stack.of(self)
        self.key = kms.Key(
            self,
            "Key",
            description="Encrypts the VAHR alarm topic",
            enable_key_rotation=True,
            removal_policy=cdk.RemovalPolicy.DESTROY,
        )
        # CloudWatch publishes the alarms to the encrypted topic, for this account's alarms.
        self.key.add_to_resource_policy(
            iam.PolicyStatement(
                sid="CloudWatchAlarmsOfThisAccount",
                principals=[iam.ServicePrincipal("cloudwatch.amazonaws.com")],
                actions=["kms:Decrypt", "kms:GenerateDataKey*"],
                resources=["*"],
                conditions={
                    "StringEquals": {"aws:SourceAccount": stack.account},
                    "ArnLike": {
                        "aws:SourceArn": stack.format_arn(
                            service="cloudwatch",
                            resource="alarm",
                            resource_name="*",
                            arn_format=cdk.ArnFormat.COLON_RESOURCE_NAME,
                        )
                    },
                },
            )
        )
        self.topic = sns.Topic(
            self,
            "Topic",
            display_name="VAHR alarms",
            master_key=self.key,
            enforce_ssl=True,
        )
        self.alarms: list[cloudwatch.Alarm] = []
        if email is not None:
            self.topic.add_subscription(subscriptions.EmailSubscription(email))

    def watch_queue(self, name: str, queue: sqs.IQueue) -> None:
        """Alarm when the dead-letter queue holds any message."""
        self._alarm(
            f"{name}DeadLetters",
            queue.metric_approximate_number_of_messages_visible(period=PERIOD, statistic="Maximum"),
            f"VAHR: {name}'s dead-letter queue holds messages nothing took",
        )

    def watch_function(self, name: str, function: lambda_.IFunction) -> None:
        """Alarm on any error and any throttle of the function."""
        self._alarm(
            f"{name}Errors",
            function.metric_errors(period=PERIOD, statistic="Sum"),
            f"VAHR: the {name} function failed",
        )
        self._alarm(
            f"{name}Throttles",
            function.metric_throttles(period=PERIOD, statistic="Sum"),
            f"VAHR: the {name} function was throttled",
        )

    def _alarm(self, construct_id: str, metric: cloudwatch.IMetric, description: str) -> None:
        alarm = cloudwatch.Alarm(
            self,
            construct_id,
            metric=metric,
            threshold=1,
            evaluation_periods=1,
            comparison_operator=cloudwatch.ComparisonOperator.GREATER_THAN_OR_EQUAL_TO_THRESHOLD,
            treat_missing_data=cloudwatch.TreatMissingData.NOT_BREACHING,
            alarm_description=description,
        )
        alarm.add_alarm_action(actions.SnsAction(self.topic))
        self.alarms.append(alarm)
