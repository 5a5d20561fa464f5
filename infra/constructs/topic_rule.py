"""An IoT topic rule that invokes a Lambda function, its failures kept in a dead-letter queue.

The announcer's and the dispatcher's rules are this shape: the robots' MQTT traffic selected
by SQL, one Lambda action, and an SQS error action so that no event the function could not
take is lost silently.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from aws_cdk import aws_iot as iot

if TYPE_CHECKING:
    from aws_cdk import aws_iam as iam
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
