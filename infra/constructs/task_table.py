"""The fleet's task queue: one DynamoDB table, read and written only by the dispatcher.

Its layout (partition `section`, sort `id`; open tasks, closed tasks, robots' claims) is
the dispatcher's (lambda/dispatcher/task_table.py). On demand, since tasks come when people
speak; point-in-time recovery, since the queue is state a restart must find; encrypted at
rest with a key DynamoDB manages; closed tasks expire through the table's TTL on
`expires_at`. With deletion protection (`-c taskTableDeletionProtection=true`) the table
is also retained when the stack is destroyed.
"""

from __future__ import annotations

import aws_cdk as cdk
from aws_cdk import aws_dynamodb as dynamodb
from constructs import Construct

PARTITION_KEY = "section"
SORT_KEY = "id"
TTL_ATTRIBUTE = "expires_at"


class TaskTable(Construct):
    """The table; `table` is the `dynamodb.Table`."""

    def __init__(self, scope: Construct, construct_id: str, *, deletion_protection: bool) -> None:
        super().__init__(scope, construct_id)
        self.table = dynamodb.Table(
            self,
            "Table",
            partition_key=dynamodb.Attribute(
                name=PARTITION_KEY, type=dynamodb.AttributeType.STRING
            ),
            sort_key=dynamodb.Attribute(name=SORT_KEY, type=dynamodb.AttributeType.STRING),
            billing_mode=dynamodb.BillingMode.PAY_PER_REQUEST,
            point_in_time_recovery_specification=dynamodb.PointInTimeRecoverySpecification(
                point_in_time_recovery_enabled=True
            ),
            encryption=dynamodb.TableEncryption.AWS_MANAGED,
            time_to_live_attribute=TTL_ATTRIBUTE,
            deletion_protection=deletion_protection,
            removal_policy=(
                cdk.RemovalPolicy.RETAIN if deletion_protection else cdk.RemovalPolicy.DESTROY
            ),
        )
