"""The topic rule that turns a robot's presence message into `reported.connected`.

A robot publishes `{"online": true}` on connect and leaves `{"online": false}` as its last
will, on `vahr/robots/{thing}/presence`. The rule rewrites it into a shadow update for that
thing, so the skill sees `connected` without the robot having to report it twice (and
sees `false` when the robot vanished without saying goodbye).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_iam as iam
from aws_cdk import aws_iot as iot
from constructs import Construct

from infra.constructs.topic_rule import rule_role
from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Sequence

# vahr/robots/{thing}/presence: the thing name is the third topic level.
_THING_LEVEL = 3


def presence_sql() -> str:
    """The rule query: keep boolean `online` only, shape it as a shadow update document."""
    return (
        "SELECT {'reported': {'connected': online}} AS state "
        f"FROM '{topics.ALL_PRESENCE}' WHERE isBoolean(online)"
    )


def republish_topic() -> str:
    """The shadow update topic of the robot that sent the presence message.

    `$$` is how a republish action writes a literal `$` before a substitution template.
    """
    template = topics.shadow("VAHRRULETHING", "update").replace(
        "VAHRRULETHING", f"${{topic({_THING_LEVEL})}}"
    )
    return "$" + template


class PresenceRule(Construct):
    """The rule and its role, allowed to publish only to the fleet's shadow update topics."""

    def __init__(
        self, scope: Construct, construct_id: str, *, rule_name: str, things: Sequence[str]
    ) -> None:
        super().__init__(scope, construct_id)
        stack = cdk.Stack.of(self)
        self.role = rule_role(
            self,
            "Role",
            rule_names=[rule_name],
            description="Lets the VAHR presence rule update the fleet's shadows",
        )
        # One statement, one ARN per robot: a presence message for any other thing name is
        # denied rather than creating a shadow.
        self.role.add_to_policy(
            iam.PolicyStatement(
                actions=["iot:Publish"],
                resources=[
                    stack.format_arn(
                        service="iot",
                        resource="topic",
                        resource_name=topics.shadow(thing, "update"),
                    )
                    for thing in things
                ],
            )
        )
        self.rule = iot.CfnTopicRule(
            self,
            "Rule",
            rule_name=rule_name,
            topic_rule_payload=iot.CfnTopicRule.TopicRulePayloadProperty(
                sql=presence_sql(),
                aws_iot_sql_version="2016-03-23",
                rule_disabled=False,
                description="Robot presence -> reported.connected in its classic shadow",
                actions=[
                    iot.CfnTopicRule.ActionProperty(
                        republish=iot.CfnTopicRule.RepublishActionProperty(
                            topic=republish_topic(),
                            role_arn=self.role.role_arn,
                            qos=1,
                        )
                    )
                ],
            ),
        )
