"""The one IoT policy every robot certificate carries, written with policy variables.

A robot connects as its own thing and may touch only its own command topic, events,
presence and classic shadow, plus the fleet command topic and its peers' events and
presence (read only). Topic strings come from `vahr.protocol.topics`; this module only
turns them into IoT policy resources.
"""

from __future__ import annotations

from typing import Any

import aws_cdk as cdk
from aws_cdk import aws_iot as iot
from constructs import Construct

from vahr.protocol import topics

THING_VARIABLE = "${iot:Connection.Thing.ThingName}"
# A valid thing name that appears nowhere else, so topics.* can build the strings and the
# policy variable (which `check_thing` rightly rejects) is put in afterwards.
_MARK = "VAHRPOLICYTHING"

# What a robot sends to its own shadow, and the answers it listens for.
SHADOW_REQUESTS = topics.SHADOW_REQUESTS
SHADOW_RESPONSES = topics.SHADOW_RESPONSES


def _own(topic: str) -> str:
    return topic.replace(_MARK, THING_VARIABLE)


def _any_robot(topic: str) -> str:
    # `+` is literal in IoT policy resources; `*` is the policy wildcard.
    return topic.replace("+", "*")


def robot_topics() -> dict[str, list[str]]:
    """The topics and filters a robot may use, by IoT action (before ARN prefixes)."""
    publish = [
        _own(topics.robot_events(_MARK)),
        _own(topics.robot_presence(_MARK)),
        *(_own(topics.shadow(_MARK, op)) for op in SHADOW_REQUESTS),
    ]
    listen = [
        _own(topics.robot_cmd(_MARK)),
        topics.FLEET_CMD,
        # The zones closed now, retained by the dispatcher function (read only).
        topics.FLEET_ZONES,
        _any_robot(topics.ALL_EVENTS),
        _any_robot(topics.ALL_PRESENCE),
        *(_own(topics.shadow(_MARK, op)) for op in SHADOW_RESPONSES),
    ]
    return {
        "publish": publish,
        # Retained so a peer that connects later still learns who is online (presence,
        # also the last will) and who has already delivered (the `delivered` event, which
        # a sequential delivery waits for).
        "retain": [_own(topics.robot_events(_MARK)), _own(topics.robot_presence(_MARK))],
        "subscribe": listen,
        "receive": listen,
    }


def robot_policy_document(*, arn_prefix: str, role_alias_arn: str | None = None) -> dict[str, Any]:
    """The policy document; `arn_prefix` is `arn:<partition>:iot:<region>:<account>`."""
    allowed = robot_topics()

    def arns(kind: str, names: list[str]) -> list[str]:
        return [f"{arn_prefix}:{kind}/{name}" for name in names]

    statements: list[dict[str, Any]] = [
        {
            "Sid": "ConnectAsOwnThing",
            "Effect": "Allow",
            "Action": "iot:Connect",
            "Resource": f"{arn_prefix}:client/{THING_VARIABLE}",
            # The client id must be the name of a thing this certificate is attached to.
            "Condition": {"Bool": {"iot:Connection.Thing.IsAttached": "true"}},
        },
        {
            "Sid": "PublishOwnEventsPresenceShadow",
            "Effect": "Allow",
            "Action": "iot:Publish",
            "Resource": arns("topic", allowed["publish"]),
        },
        {
            "Sid": "RetainOwnEventsPresence",
            "Effect": "Allow",
            "Action": "iot:RetainPublish",
            "Resource": arns("topic", allowed["retain"]),
        },
        {
            "Sid": "SubscribeCommandsPeersShadow",
            "Effect": "Allow",
            "Action": "iot:Subscribe",
            "Resource": arns("topicfilter", allowed["subscribe"]),
        },
        {
            "Sid": "ReceiveCommandsPeersShadow",
            "Effect": "Allow",
            "Action": "iot:Receive",
            "Resource": arns("topic", allowed["receive"]),
        },
    ]
    if role_alias_arn is not None:
        statements.append(
            {
                "Sid": "ExchangeCertificateForLexCredentials",
                "Effect": "Allow",
                "Action": "iot:AssumeRoleWithCertificate",
                "Resource": role_alias_arn,
            }
        )
    return {"Version": "2012-10-17", "Statement": statements}


class RobotPolicy(Construct):
    """`AWS::IoT::Policy` named `policy_name`, attached to each robot's certificate."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        policy_name: str,
        role_alias_arn: str | None = None,
    ) -> None:
        super().__init__(scope, construct_id)
        arn_prefix = f"arn:{cdk.Aws.PARTITION}:iot:{cdk.Aws.REGION}:{cdk.Aws.ACCOUNT_ID}"
        self.policy_name = policy_name
        self.policy = iot.CfnPolicy(
            self,
            "Policy",
            policy_name=policy_name,
            policy_document=robot_policy_document(
                arn_prefix=arn_prefix, role_alias_arn=role_alias_arn
            ),
        )
