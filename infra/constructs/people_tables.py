"""Who may do what on AWS, and the trail of what was done: two DynamoDB tables.

- The users table (with `-c people=true`): one item per person (`id`, their Alexa userId
  or personId; `name`; `role`) and everyone else's role under id `*`, loaded from a users
  file by `vahr users import FILE --table NAME` (lambda/skill/users_table.py). The skill
  reads it with GetItem, nothing more. Without it everyone may do everything, as before.
- The audit table (always): the hash-chained trail of every request the skill acted on and
  every task the dispatcher gave by itself (key `trail` and `seq`; vahr/protocol/audit.py).
  Point-in-time recovery keeps 35 days of its past, and deletion protection (on unless
  `-c auditTableDeletionProtection=false`) keeps it through `cdk destroy`. Its writers may
  put items (each append is a transaction of two conditional puts: a record whose number
  is free, and the head if it is unchanged) and read the trail's head item, nothing more:
  no update, no delete, no scan. `vahr audit --table NAME` reads it with your credentials.

Both are on demand, since people speak when they speak, and encrypted at rest with a key
DynamoDB manages.
"""

from __future__ import annotations

import aws_cdk as cdk
from aws_cdk import aws_dynamodb as dynamodb
from aws_cdk import aws_iam as iam
from constructs import Construct

from vahr.protocol.audit import TRAIL_HEAD

USERS_KEY = "id"
TRAIL_KEY = "trail"
TRAIL_SORT_KEY = "seq"


class PeopleTables(Construct):
    """The users table (`users`, None without people) and the audit table (`audit`)."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        people: bool,
        audit_deletion_protection: bool,
    ) -> None:
        super().__init__(scope, construct_id)
        recovery = dynamodb.PointInTimeRecoverySpecification(point_in_time_recovery_enabled=True)
        self.users = (
            dynamodb.Table(
                self,
                "Users",
                partition_key=dynamodb.Attribute(
                    name=USERS_KEY, type=dynamodb.AttributeType.STRING
                ),
                billing_mode=dynamodb.BillingMode.PAY_PER_REQUEST,
                point_in_time_recovery_specification=recovery,
                encryption=dynamodb.TableEncryption.AWS_MANAGED,
                removal_policy=cdk.RemovalPolicy.DESTROY,
            )
            if people
            else None
        )
        self.audit = dynamodb.Table(
            self,
            "Audit",
            partition_key=dynamodb.Attribute(name=TRAIL_KEY, type=dynamodb.AttributeType.STRING),
            sort_key=dynamodb.Attribute(name=TRAIL_SORT_KEY, type=dynamodb.AttributeType.NUMBER),
            billing_mode=dynamodb.BillingMode.PAY_PER_REQUEST,
            point_in_time_recovery_specification=recovery,
            encryption=dynamodb.TableEncryption.AWS_MANAGED,
            deletion_protection=audit_deletion_protection,
            removal_policy=(
                cdk.RemovalPolicy.RETAIN if audit_deletion_protection else cdk.RemovalPolicy.DESTROY
            ),
        )

    def admit_reader_of_people(self, role: iam.IRole) -> None:
        """`role` may read one person at a time from the users table."""
        if self.users is None:
            return
        role.add_to_principal_policy(
            iam.PolicyStatement(
                sid="ReadPeople",
                actions=["dynamodb:GetItem"],
                resources=[self.users.table_arn],
            )
        )

    def admit_trail_writer(self, role: iam.IRole) -> None:
        """`role` may append to the trail: put items, and read the head item alone."""
        role.add_to_principal_policy(
            iam.PolicyStatement(
                sid="AppendToTheTrail",
                actions=["dynamodb:PutItem"],
                resources=[self.audit.table_arn],
            )
        )
        role.add_to_principal_policy(
            iam.PolicyStatement(
                sid="ReadTheTrailsHead",
                actions=["dynamodb:GetItem"],
                resources=[self.audit.table_arn],
                conditions={"ForAllValues:StringEquals": {"dynamodb:LeadingKeys": [TRAIL_HEAD]}},
            )
        )
