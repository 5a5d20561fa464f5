"""The DynamoDB tables the stack makes, created in moto with the stack's keys: the audit
trail (infra/constructs/people_tables.py) and the dispatcher's tasks
(infra/constructs/task_table.py)."""

from __future__ import annotations

from typing import Any


def create_audit_table(client: Any, name: str) -> None:
    """The audit table: partition `trail`, sort `seq` (a number)."""
    _create(client, name, ("trail", "S"), ("seq", "N"))


def create_task_table(client: Any, name: str) -> None:
    """The dispatcher's task table: partition `section`, sort `id`."""
    _create(client, name, ("section", "S"), ("id", "S"))


def _create(client: Any, name: str, partition: tuple[str, str], sort: tuple[str, str]) -> None:
    client.create_table(
        TableName=name,
        KeySchema=[
            {"AttributeName": partition[0], "KeyType": "HASH"},
            {"AttributeName": sort[0], "KeyType": "RANGE"},
        ],
        AttributeDefinitions=[
            {"AttributeName": key, "AttributeType": kind} for key, kind in (partition, sort)
        ],
        BillingMode="PAY_PER_REQUEST",
    )
