"""The audit trail on AWS (DynamoDB): records appended, chained, never changed.

The items and the append (one transaction of two conditional puts, tried again on a lost
race, so concurrent functions never fork the chain) are `vahr.protocol.audit`'s, shared
with the dispatcher function; this module makes the calls. The skill's role may only put
items and read the head (infra/constructs/people_tables.py): nothing of the skill updates or
deletes. `vahr audit --table` reads the records and the head and verifies them
(`vahr.protocol.audit.verify`). Point-in-time recovery keeps 35 days of the table's past.
"""

from __future__ import annotations

import random
import time
from typing import TYPE_CHECKING, Any

import boto3
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from skill.errors import TrailUnavailable
from vahr.protocol.audit import (
    APPEND_ATTEMPTS,
    HEAD_KEY,
    TRAIL_RECORDS,
    append_chained,
    appended_items,
    head_from_item,
    record_from_item,
)

if TYPE_CHECKING:
    from vahr.protocol.audit import AuditEntry, AuditRecord, TrailHead

TIMEOUT_S = 2.0


class AuditTable:
    """`Trail` over the DynamoDB audit table."""

    def __init__(self, table_name: str, client: Any = None) -> None:
        self.table_name = table_name
        self.client = client or boto3.client(
            "dynamodb",
            config=Config(
                connect_timeout=TIMEOUT_S, read_timeout=TIMEOUT_S, retries={"max_attempts": 2}
            ),
        )

    def head(self) -> TrailHead | None:
        try:
            answer = self.client.get_item(
                TableName=self.table_name, Key=HEAD_KEY, ConsistentRead=True
            )
        except (BotoCoreError, ClientError) as err:
            raise TrailUnavailable(f"the audit table cannot be read: {err}") from err
        return head_from_item(answer.get("Item"))

    def append(self, entry: AuditEntry) -> AuditRecord:
        record = append_chained(entry, self.head, self._put, pause=_jitter)
        if record is None:
            raise TrailUnavailable(f"the audit trail stayed busy for {APPEND_ATTEMPTS} attempts")
        return record

    def _put(self, record: AuditRecord, head: TrailHead | None) -> bool:
        """The record and the new head in one transaction; False when another won."""
        items = appended_items(record, head)
        for item in items:
            item["Put"]["TableName"] = self.table_name
        try:
            self.client.transact_write_items(TransactItems=items)
        except ClientError as err:
            if err.response.get("Error", {}).get("Code") == "TransactionCanceledException":
                return False
            raise TrailUnavailable(f"the audit table refused the record: {err}") from err
        except BotoCoreError as err:
            raise TrailUnavailable(f"the audit table cannot be written: {err}") from err
        return True

    def records(self, after: int = 0, limit: int | None = None) -> list[AuditRecord]:
        """The records numbered above `after`, in order, at most `limit` (an item that is no
        record raises ProtocolError)."""
        found: list[AuditRecord] = []
        query: dict[str, Any] = {
            "TableName": self.table_name,
            "KeyConditionExpression": "trail = :records AND seq > :after",
            "ExpressionAttributeValues": {
                ":records": {"S": TRAIL_RECORDS},
                ":after": {"N": str(after)},
            },
            "ConsistentRead": True,
        }
        try:
            for page in self.client.get_paginator("query").paginate(**query):
                found += [record_from_item(item) for item in page.get("Items", [])]
                if limit is not None and len(found) >= limit:
                    return found[:limit]
        except (BotoCoreError, ClientError) as err:
            raise TrailUnavailable(f"the audit table cannot be read: {err}") from err
        return found

    def snapshot(self, after: int, limit: int) -> tuple[list[AuditRecord], TrailHead | None]:
        """Up to `limit` records above `after`, and the head read after them (so it is never
        older than they are)."""
        records = self.records(after, limit)
        return records, self.head()


def _jitter(attempt: int) -> None:
    # Another function appended first: wait a moment before chaining after its record.
    time.sleep(random.uniform(0, 0.02 * (attempt + 1)))  # noqa: S311 - jitter only
