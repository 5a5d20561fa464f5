"""An IoT topic rule that invokes a Lambda function, its failures kept in a dead-letter queue,
and the role a rule acts with.

The announcer's and the dispatcher's rules are this shape: the robots' MQTT traffic selected
by SQL, one Lambda action, and an SQS error action so that no event the function could not
take is lost silently. Every rule's role (theirs and the presence rule's) is `rule_role`:
only AWS IoT may assume it, and only for the named rules of this account
(`aws:SourceAccount` and `aws:SourceArn`), so no other account's rule can act with it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_iam as iam
from aws_cdk import aws_iot as iot

if TYPE_CHECKING:
    from collections.abc import Sequence

    from aws_cdk import aws_lambda as lambda_
    from aws_cdk import aws_sqs as sqs
    from constructs import Construct

SQL_VERSION = "2016-03-23"


def lambda_topic_rule(
    scope: Construct,
    construct_id: str,
    *,
    name: str,
    sql: str,
    description: str,
    function: lambda_.IFunction,
    dead_letters: sqs.IQueue,
    role: iam.IRole,
) -> iot.CfnTopicRule:
    """A rule named `name` sending what `sql` selects to `function`; what fails goes to
    `dead_letters`, sent with `role`."""
    return iot.CfnTopicRule(
        scope,
        construct_id,
        rule_name=name,
        topic_rule_payload=iot.CfnTopicRule.TopicRulePayloadProperty(
            sql=sql,
            aws_iot_sql_version=SQL_VERSION,
            rule_disabled=False,
            description=description,
            actions=[
                iot.CfnTopicRule.ActionProperty(
                    lambda_=iot.CfnTopicRule.LambdaActionProperty(
                        function_arn=function.function_arn
                    )
                )
            ],
            error_action=iot.CfnTopicRule.ActionProperty(
                sqs=iot.CfnTopicRule.SqsActionProperty(
                    queue_url=dead_letters.queue_url, role_arn=role.role_arn, use_base64=False
                )
            ),
        ),
    )


def rule_role(
    scope: Construct, construct_id: str, *, rule_names: Sequence[str], description: str
) -> iam.Role:
    """A role AWS IoT may assume only for the rules `rule_names` of this account."""
    stack = cdk.Stack.of(scope)
    arns = [
        stack.format_arn(service="iot", resource="rule", resource_name=name) for name in rule_names
    ]
    return iam.Role(
        scope,
        construct_id,
        assumed_by=iot_principal(scope, source_arn=arns[0] if len(arns) == 1 else arns, like=False),
        description=description,
    )


def iot_principal(scope: Construct, *, source_arn: str | list[str], like: bool) -> iam.IPrincipal:
    """`iot.amazonaws.com`, acting for this account and for `source_arn` only (`like`: the
    ARN is a pattern, `arn:...:iot:region:account:*`)."""
    account = cdk.Stack.of(scope).account
    return iam.ServicePrincipal("iot.amazonaws.com").with_conditions(
        {
            "StringEquals": {"aws:SourceAccount": account},
            "ArnLike" if like else "ArnEquals": {"aws:SourceArn": source_arn},
        }
    )
