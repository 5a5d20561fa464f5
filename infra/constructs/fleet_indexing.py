"""Fleet indexing: the robots' classic shadows searchable by status and zone.

There is no CloudFormation resource for it: a custom resource calls
`iot:UpdateIndexingConfiguration` at deploy time, turning on thing indexing with the
registry and the classic shadow (REGISTRY_AND_SHADOW) and five custom fields,
`shadow.reported.status` and `shadow.reported.zone` (String), `shadow.reported.connected`
(Boolean), and the battery, `shadow.reported.battery.percent` (Number) and
`shadow.reported.battery.charging` (Boolean), which `SearchIndex` matches exactly (and
numbers by range, `shadow.reported.battery.percent:[0 TO 20]`) and `GetBucketsAggregation`
and `GetStatistics` can count by (the dispatcher searches by status, connection and zone;
the skill's status summary counts by status and connection). Connectivity indexing stays off: the
robots' shadows report `connected` themselves (the presence rule keeps it true to the MQTT
session).

The configuration belongs to the account and region, not to the stack: deploying sets it
(replacing any other), destroying the stack turns thing indexing off again. The index
takes minutes to build after the first deploy (docs/deploy.md says how to see it ACTIVE).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
from aws_cdk import aws_iam as iam
from aws_cdk import custom_resources as cr
from constructs import Construct

if TYPE_CHECKING:
    from aws_cdk import aws_logs as logs

INDEX_NAME = "AWS_Things"
CUSTOM_FIELDS = (
    ("shadow.reported.status", "String"),
    ("shadow.reported.zone", "String"),
    ("shadow.reported.connected", "Boolean"),
    ("shadow.reported.battery.percent", "Number"),
    ("shadow.reported.battery.charging", "Boolean"),
)


def indexing_configuration(mode: str = "REGISTRY_AND_SHADOW") -> dict[str, Any]:
    """The UpdateIndexingConfiguration request (the JavaScript SDK's parameter names)."""
    configuration: dict[str, Any] = {"thingIndexingMode": mode}
    if mode != "OFF":
        configuration["thingConnectivityIndexingMode"] = "OFF"
        configuration["customFields"] = [
            {"name": name, "type": kind} for name, kind in CUSTOM_FIELDS
        ]
    return {"thingIndexingConfiguration": configuration}


class FleetIndexing(Construct):
    """The account's thing indexing configuration; `index_arn` is `AWS_Things`'s ARN."""

    def __init__(
        self, scope: Construct, construct_id: str, *, provider_logs: logs.ILogGroup
    ) -> None:
        super().__init__(scope, construct_id)

        def call(mode: str) -> cr.AwsSdkCall:
            return cr.AwsSdkCall(
                service="Iot",
                action="updateIndexingConfiguration",
                parameters=indexing_configuration(mode),
                physical_resource_id=cr.PhysicalResourceId.of("vahr-fleet-indexing"),
            )

        self.configuration = cr.AwsCustomResource(
            self,
            "Configuration",
            on_create=call("REGISTRY_AND_SHADOW"),
            on_update=call("REGISTRY_AND_SHADOW"),
            on_delete=call("OFF"),
            # iot:UpdateIndexingConfiguration has no resource type: IAM accepts only "*".
            policy=cr.AwsCustomResourcePolicy.from_statements(
                [iam.PolicyStatement(actions=["iot:UpdateIndexingConfiguration"], resources=["*"])]
            ),
            install_latest_aws_sdk=False,
            log_group=provider_logs,
        )
        self.index_arn = cdk.Stack.of(self).format_arn(
            service="iot", resource="index", resource_name=INDEX_NAME
        )
