"""AWS IoT Core's own logging, at ERROR: refused connections, denied publishes and failed rule
actions land in CloudWatch Logs (`AWSIotLogsV2`), where an operator and the alarms can see
them.

It is the account's one logging configuration in the region (`AWS::IoT::Logging`); where
another stack already owns it, deploy with `-c iotLogging=false`. The role AWS IoT writes
the logs with trusts `iot.amazonaws.com` for this account only, and may write only that
log group, which keeps the configured retention.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_iam as iam
from aws_cdk import aws_iot as iot
from aws_cdk import aws_logs as logs
from constructs import Construct

from infra.config import LOG_RETENTION_NAMES
from infra.constructs.topic_rule import iot_principal

if TYPE_CHECKING:
    from infra.config import InfraConfig

LOG_GROUP = "AWSIotLogsV2"  # the group AWS IoT's v2 logging writes to; its name is fixed
LEVEL = "ERROR"


class IotLogging(Construct):
    """`AWS::IoT::Logging` at `LEVEL`, its role, and the log group it writes."""

    def __init__(self, scope: Construct, construct_id: str, *, config: InfraConfig) -> None:
        super().__init__(scope, construct_id)
        stack = cdk.Stack.of(self)
        self.log_group = logs.LogGroup(
            self,
            "Logs",
            log_group_name=LOG_GROUP,
            retention=logs.RetentionDays[LOG_RETENTION_NAMES[config.log_retention_days]],
            removal_policy=cdk.RemovalPolicy.DESTROY,
        )
        self.role = iam.Role(
            self,
            "Role",
            assumed_by=iot_principal(
                self,
                source_arn=stack.format_arn(service="iot", resource="*", resource_name=None),
                like=True,
            ),
            description="Lets AWS IoT write its error log (AWSIotLogsV2)",
        )
        self.log_group.grant_write(self.role)
        self.logging = iot.CfnLogging(
            self,
            "Logging",
            account_id=stack.account,
            role_arn=self.role.role_arn,
            default_log_level=LEVEL,
        )
        # The role's policy must exist before AWS IoT is told to use it.
        self.logging.node.add_dependency(self.role)
