"""A scheduled AWS IoT Device Defender audit of what the fleet's security rests on.

Daily, three checks: an IoT policy that allows more than it should
(`IOT_POLICY_OVERLY_PERMISSIVE_CHECK`), one certificate used by several devices at once
(`DEVICE_CERTIFICATE_SHARED_CHECK`), and one client id used by several connections
(`CONFLICTING_CLIENT_IDS_CHECK`: a takeover's trace). Findings are sent to the alarm topic.

The audit configuration is the account's one in the region (`AWS::IoT::AccountAuditConfiguration`);
where another stack owns it, or the account has no Device Defender, deploy with
`-c deviceDefenderAudit=false`. The audit's role trusts `iot.amazonaws.com` for this account
only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_iam as iam
from aws_cdk import aws_iot as iot
from constructs import Construct

from infra.constructs.topic_rule import iot_principal

if TYPE_CHECKING:
    from aws_cdk import aws_kms as kms
    from aws_cdk import aws_sns as sns

CHECKS = (
    "IOT_POLICY_OVERLY_PERMISSIVE_CHECK",
    "DEVICE_CERTIFICATE_SHARED_CHECK",
    "CONFLICTING_CLIENT_IDS_CHECK",
)
FREQUENCY = "DAILY"
AUDIT_POLICY = "service-role/AWSIoTDeviceDefenderAudit"


class DeviceAudit(Construct):
    """The account's audit configuration (these checks on), its role, and the schedule."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        audit_name: str,
        findings: sns.ITopic,
        findings_key: kms.IKey,
    ) -> None:
        super().__init__(scope, construct_id)
        stack = cdk.Stack.of(self)
        account_wide = stack.format_arn(service="iot", resource="*", resource_name=None)
        self.role = iam.Role(
            self,
            "Role",
            assumed_by=iot_principal(self, source_arn=account_wide, like=True),
            description="Lets AWS IoT Device Defender read the IoT configuration it audits",
            managed_policies=[iam.ManagedPolicy.from_aws_managed_policy_name(AUDIT_POLICY)],
        )
        self.notify_role = iam.Role(
            self,
            "NotifyRole",
            assumed_by=iot_principal(self, source_arn=account_wide, like=True),
            description="Lets AWS IoT Device Defender send audit findings to the alarm topic",
        )
        # Publishing to the encrypted topic: the topic, and its key's two uses SNS makes.
        self.notify_role.add_to_policy(
            iam.PolicyStatement(actions=["sns:Publish"], resources=[findings.topic_arn])
        )
        self.notify_role.add_to_policy(
            iam.PolicyStatement(
                actions=["kms:GenerateDataKey", "kms:Decrypt"], resources=[findings_key.key_arn]
            )
        )
        enabled = iot.CfnAccountAuditConfiguration.AuditCheckConfigurationProperty(enabled=True)
        self.configuration = iot.CfnAccountAuditConfiguration(
            self,
            "Configuration",
            account_id=stack.account,
            role_arn=self.role.role_arn,
            audit_check_configurations=iot.CfnAccountAuditConfiguration.AuditCheckConfigurationsProperty(
                iot_policy_overly_permissive_check=enabled,
                device_certificate_shared_check=enabled,
                conflicting_client_ids_check=enabled,
            ),
            audit_notification_target_configurations=iot.CfnAccountAuditConfiguration.AuditNotificationTargetConfigurationsProperty(
                sns=iot.CfnAccountAuditConfiguration.AuditNotificationTargetProperty(
                    enabled=True,
                    role_arn=self.notify_role.role_arn,
                    target_arn=findings.topic_arn,
                )
            ),
        )
        self.configuration.node.add_dependency(self.role, self.notify_role)
        self.schedule = iot.CfnScheduledAudit(
            self,
            "Schedule",
            scheduled_audit_name=audit_name,
            frequency=FREQUENCY,
            target_check_names=list(CHECKS),
        )
        # A scheduled audit needs the checks it names turned on first.
        self.schedule.node.add_dependency(self.configuration)
