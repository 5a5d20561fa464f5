"""An account's AWS IoT endpoint address, looked up at deploy time (it differs per account)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from aws_cdk import aws_iam as iam
from aws_cdk import custom_resources as cr
from constructs import Construct

if TYPE_CHECKING:
    from aws_cdk import aws_logs as logs


class IotEndpoint(Construct):
    """`describeEndpoint` for `endpoint_type` (`iot:Data-ATS`, `iot:CredentialProvider`)."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        endpoint_type: str,
        provider_logs: logs.ILogGroup,
    ) -> None:
        super().__init__(scope, construct_id)
        call = cr.AwsSdkCall(
            service="Iot",
            action="describeEndpoint",
            parameters={"endpointType": endpoint_type},
            physical_resource_id=cr.PhysicalResourceId.of(endpoint_type),
        )
        lookup = cr.AwsCustomResource(
            self,
            "Lookup",
            on_create=call,
            on_update=call,
            # iot:DescribeEndpoint has no resource type: IAM accepts only "*" for it.
            policy=cr.AwsCustomResourcePolicy.from_statements(
                [iam.PolicyStatement(actions=["iot:DescribeEndpoint"], resources=["*"])]
            ),
            install_latest_aws_sdk=False,
            log_group=provider_logs,
        )
        self.address: str = lookup.get_response_field("endpointAddress")
