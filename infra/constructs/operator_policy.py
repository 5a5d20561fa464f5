"""The IoT policies of the people's side of the lab: the operator station and the experiment
recorder, each with certificates of its own.

Each connects only under its own client ids (the station `vahr-station-...`, the recorder,
whose connection is also the keyboard method's console, `vahr-experiment-...`), so neither
can take over a robot's session nor the other's; robots' thing names may not start with
`vahr-` (`vahr.protocol.identities`), so no robot can take over theirs. Both may send
commands to the fleet's robots and watch commands and events. The station also watches
presence, the robots' shadow documents (read only), the assistant's announcements
(`vahr/assistant/announcements`, which only the announcer function publishes) and the
session's status, and sends the participant's input; the recorder keeps the session's
status (retained, its last will clearing it) and hears the participant's input. Neither
can speak for a robot or for the assistant, and no shadow can be changed or asked for
over MQTT.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal

import aws_cdk as cdk
from aws_cdk import aws_iot as iot
from constructs import Construct

from vahr.protocol import topics
from vahr.protocol.identities import RECORDER_CLIENT_PREFIX, STATION_CLIENT_PREFIX

if TYPE_CHECKING:
    from collections.abc import Sequence

Operator = Literal["station", "recorder"]
CLIENT_ID_PREFIXES: dict[Operator, str] = {
    "station": STATION_CLIENT_PREFIX,
    "recorder": RECORDER_CLIENT_PREFIX,
}


def operator_policy_document(
    operator: Operator, *, arn_prefix: str, things: Sequence[str]
) -> dict[str, Any]:
    """The policy document of `operator`; `arn_prefix` is
    `arn:<partition>:iot:<region>:<account>`."""
    commands = [*(topics.robot_cmd(thing) for thing in things), topics.FLEET_CMD]
    watch = [topics.ALL_EVENTS.replace("+", "*"), *commands]
    # Filters with MQTT's `+` are literal in a topicfilter resource: these allow exactly the
    # wildcard subscriptions the recorder and the station make; what they receive through
    # them is still limited to the topics listed for iot:Receive.
    filters = [topics.ALL_ROBOT_CMDS]
    published: list[str] = []
    heard: list[str] = []
    if operator == "station":
        watch.append(topics.ALL_PRESENCE.replace("+", "*"))
        filters.append(topics.ALL_SHADOW_DOCUMENTS)
        published.append(topics.EXPERIMENT_INPUT)
        heard += [topics.EXPERIMENT_STATUS, topics.ASSISTANT_ANNOUNCEMENTS]
        received = [*(topics.shadow(thing, "update/documents") for thing in things)]
    else:
        published.append(topics.EXPERIMENT_STATUS)
        heard.append(topics.EXPERIMENT_INPUT)
        received = []

    def arns(kind: str, names: Sequence[str]) -> list[str]:
        return [f"{arn_prefix}:{kind}/{name}" for name in names]

    statements: list[dict[str, Any]] = [
        {
            "Sid": "ConnectUnderOwnClientIds",
            "Effect": "Allow",
            "Action": "iot:Connect",
            "Resource": f"{arn_prefix}:client/{CLIENT_ID_PREFIXES[operator]}*",
        },
        {
            "Sid": "CommandTheFleet",
            "Effect": "Allow",
            "Action": "iot:Publish",
            "Resource": arns("topic", [*commands, *published]),
        },
        {
            "Sid": "Watch",
            "Effect": "Allow",
            "Action": "iot:Subscribe",
            "Resource": arns("topicfilter", [*watch, *filters, *heard]),
        },
        {
            "Sid": "Receive",
            "Effect": "Allow",
            "Action": "iot:Receive",
            "Resource": arns("topic", [*watch, *received, *heard]),
        },
    ]
    if operator == "recorder":
        statements.append(
            {
                "Sid": "KeepTheSessionStatus",
                "Effect": "Allow",
                "Action": "iot:RetainPublish",
                "Resource": f"{arn_prefix}:topic/{topics.EXPERIMENT_STATUS}",
            }
        )
    return {"Version": "2012-10-17", "Statement": statements}


class OperatorPolicy(Construct):
    """`AWS::IoT::Policy` named `policy_name`, for the station's or the recorder's certificates."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        operator: Operator,
        policy_name: str,
        things: Sequence[str],
    ) -> None:
        super().__init__(scope, construct_id)
        arn_prefix = f"arn:{cdk.Aws.PARTITION}:iot:{cdk.Aws.REGION}:{cdk.Aws.ACCOUNT_ID}"
        self.policy_name = policy_name
        self.policy = iot.CfnPolicy(
            self,
            "Policy",
            policy_name=policy_name,
            policy_document=operator_policy_document(
                operator, arn_prefix=arn_prefix, things=things
            ),
        )
