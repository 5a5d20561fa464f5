"""The IoT policy for the people's side of the lab: the experiment recorder, the console and
the operator station.

They connect with certificates of their own (not a robot's), under client ids starting with
`vahr-experiment-`, `vahr-console-` or `vahr-station-`, so they can never take over a
robot's session. They may send commands to the fleet's robots (the keyboard method) and
watch commands, events and presence; the station also watches the robots' shadow documents
(read only) and hears the assistant's announcements (`vahr/assistant/announcements`, which
only the announcer function publishes), and the station and the recorder exchange the
session's status (retained, the recorder's last will clearing it) and the participant's
input. They cannot speak for a robot or for the assistant, and no shadow can be changed or
asked for over MQTT.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
from aws_cdk import aws_iot as iot
from constructs import Construct

from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Sequence

CLIENT_ID_PREFIXES = ("vahr-experiment-", "vahr-console-", "vahr-station-")


def operator_policy_document(*, arn_prefix: str, things: Sequence[str]) -> dict[str, Any]:
    """The policy document; `arn_prefix` is `arn:<partition>:iot:<region>:<account>`."""
    session = (topics.EXPERIMENT_STATUS, topics.EXPERIMENT_INPUT)
    # What the assistant says unprompted: heard, never said, by the people's side.
    heard = (topics.ASSISTANT_ANNOUNCEMENTS,)
    documents = [topics.shadow(thing, "update/documents") for thing in things]
    watch = [
        topics.ALL_EVENTS.replace("+", "*"),
        topics.ALL_PRESENCE.replace("+", "*"),
        *(topics.robot_cmd(thing) for thing in things),
        topics.FLEET_CMD,
    ]
    # Filters with MQTT's `+` are literal in a topicfilter resource: these allow exactly the
    # wildcard subscriptions the recorder and the station make; what they receive through
    # them is still limited to the topics listed for iot:Receive.
    wildcard_filters = [topics.ALL_ROBOT_CMDS, topics.ALL_SHADOW_DOCUMENTS]
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
                "Resource": [
                    f"{arn_prefix}:topicfilter/{topic}"
                    for topic in (*watch, *wildcard_filters, *session, *heard)
                ],
            },
            {
                "Sid": "ReceiveCommandsEventsPresence",
                "Effect": "Allow",
                "Action": "iot:Receive",
                "Resource": [
                    f"{arn_prefix}:topic/{topic}"
                    for topic in (*watch, *documents, *session, *heard)
                ],
            },
            {
                "Sid": "ShareTheSession",
                "Effect": "Allow",
                "Action": "iot:Publish",
                "Resource": [f"{arn_prefix}:topic/{topic}" for topic in session],
            },
            {
                "Sid": "KeepTheSessionStatus",
                "Effect": "Allow",
                "Action": "iot:RetainPublish",
                "Resource": f"{arn_prefix}:topic/{topics.EXPERIMENT_STATUS}",
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
