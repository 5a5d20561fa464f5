"""The IoT policy for the people's side of the lab: the experiment recorder and the console.

They connect with certificates of their own (not a robot's), under client ids starting with
`vahr-experiment-` or `vahr-console-`, so they can never take over a robot's session. They
may send commands to the fleet's robots (the keyboard method) and watch commands, events
and presence; they cannot speak for a robot or touch any shadow over MQTT.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
from aws_cdk import aws_iot as iot
from constructs import Construct

from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Sequence

CLIENT_ID_PREFIXES = ("vahr-experiment-", "vahr-console-")


def operator_policy_document(*, arn_prefix: str, things: Sequence[str]) -> dict[str, Any]:
    """The policy document; `arn_prefix` is `arn:<partition>:iot:<region>:<account>`."""
    watch = [
        topics.ALL_EVENTS.replace("+", "*"),
        topics.ALL_PRESENCE.replace("+", "*"),
        *(topics.robot_cmd(thing) for thing in things),
        topics.FLEET_CMD,
    ]
    return {
        "Version": "2012-10-17",
        "Statement": [
            {
                "Sid": "ConnectAsOperator",
                "Effect": "Allow",
                "Action": "iot:Connect",
                "Resource": [f"{arn_prefix}:client/{prefix}*" for prefix in CLIENT_ID_PREFIXES],
            },
            {
                "Sid": "CommandTheFleet",
                "Effect": "Allow",
                "Action": "iot:Publish",
                "Resource": [
                    f"{arn_prefix}:topic/{topic}"
                    for topic in (*(topics.robot_cmd(thing) for thing in things), topics.FLEET_CMD)
                ],
            },
            {
                "Sid": "WatchCommandsEventsPresence",
                "Effect": "Allow",
                "Action": "iot:Subscribe",
                "Resource": [f"{arn_prefix}:topicfilter/{topic}" for topic in watch],
            },
            {
                "Sid": "ReceiveCommandsEventsPresence",
                "Effect": "Allow",
                "Action": "iot:Receive",
                "Resource": [f"{arn_prefix}:topic/{topic}" for topic in watch],
            },
        ],
    }


class OperatorPolicy(Construct):
    """`AWS::IoT::Policy` named `policy_name`, for the recorder's and console's certificates."""

    def __init__(
        self, scope: Construct, construct_id: str, *, policy_name: str, things: Sequence[str]
    ) -> None:
        super().__init__(scope, construct_id)
        arn_prefix = f"arn:{cdk.Aws.PARTITION}:iot:{cdk.Aws.REGION}:{cdk.Aws.ACCOUNT_ID}"
        self.policy_name = policy_name
        self.policy = iot.CfnPolicy(
            self,
            "Policy",
            policy_name=policy_name,
            policy_document=operator_policy_document(arn_prefix=arn_prefix, things=things),
        )
