"""The audit trail on AWS (DynamoDB): records appended, chained, never changed.

The table's key is `trail` (S) and `seq` (N). Records are the items of partition
`records`, in `seq` order, each holding the record's JSON in `record`; the item
(`head`, 0) holds the trail's head: the last record's `last` number and `hash`.

Appending is one transaction of two conditional puts: the record, if no record has its
number yet, and the new head, if the head is still the one the record was chained to. Two
functions appending at once cannot both win: the loser's transaction is cancelled, it reads
the new head and chains again (at most `ATTEMPTS` times), so the chain never forks and no
record overwrites another. The skill's role may only put items and read the head
(infra/constructs/people.py); nothing of the skill updates or deletes. `vahr audit --table`
reads the records and the head (`read_trail`) and verifies them
(`vahr.protocol.audit.verify`). Point-in-time recovery keeps 35 days of the table's past.
"""

from __future__ import annotations

import random
import time
from typing import TYPE_CHECKING, Any

import boto3
import msgspec
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from skill.errors import TrailUnavailable
from vahr.protocol.audit import TrailHead, chained, record_from_json

if TYPE_CHECKING:
    from vahr.protocol.audit import AuditEntry, AuditRecord

RECORDS = "records"
HEAD = "head"
ATTEMPTS = 6
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
                TableName=self.table_name,
                Key={"trail": {"S": HEAD}, "seq": {"N": "0"}},
                ConsistentRead=True,
            )
        except (BotoCoreError, ClientError) as err:
            raise TrailUnavailable(f"the audit table cannot be read: {err}") from err
        item = answer.get("Item")
        if item is None:
            return None
        return TrailHead(int(item["last"]["N"]), item["hash"]["S"])

    def append(self, entry: AuditEntry) -> AuditRecord:
        for attempt in range(ATTEMPTS):
            head = self.head()
            record = chained(entry, head)
            if self._put(record, head):
                return record
            # Another function appended first: chain after its record instead.
            time.sleep(random.uniform(0, 0.02 * (attempt + 1)))  # noqa: S311 - jitter only
        raise TrailUnavailable(f"the audit trail stayed busy for {ATTEMPTS} attempts")

    def _put(self, record: AuditRecord, head: TrailHead | None) -> bool:
        """The record and the new head in one transaction; False when another won."""
        head_item = {
            "trail": {"S": HEAD},
            "seq": {"N": "0"},
            "last": {"N": str(record.seq)},
            "hash": {"S": record.hash},
        }
        if head is None:
            head_condition: dict[str, Any] = {"ConditionExpression": "attribute_not_exists(trail)"}
        else:
            head_condition = {
                "ConditionExpression": "#last = :last AND #hash = :hash",
                "ExpressionAttributeNames": {"#last": "last", "#hash": "hash"},
                "ExpressionAttributeValues": {
                    ":last": {"N": str(head.seq)},
                    ":hash": {"S": head.hash},
                },
            }
        try:
            self.client.transact_write_items(
                TransactItems=[
                    {
                        "Put": {
                            "TableName": self.table_name,
                            "Item": {
                                "trail": {"S": RECORDS},
                                "seq": {"N": str(record.seq)},
                                "record": {"S": msgspec.json.encode(record).decode()},
                            },
                            "ConditionExpression": "attribute_not_exists(trail)",
                        }
                    },
                    {"Put": {"TableName": self.table_name, "Item": head_item, **head_condition}},
                ]
            )
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
            "ExpressionAttributeValues": {":records": {"S": RECORDS}, ":after": {"N": str(after)}},
            "ConsistentRead": True,
        }
        try:
            for page in self.client.get_paginator("query").paginate(**query):
                found += [_stored(item) for item in page.get("Items", [])]
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


def _stored(item: dict[str, Any]) -> AuditRecord:
    """An item as the record it holds; its key `seq` wins over the JSON's, so a record
    moved to another number reads as altered."""
    record = record_from_json(item["record"]["S"])
    key = int(item["seq"]["N"])
    return record if record.seq == key else msgspec.structs.replace(record, seq=key)
