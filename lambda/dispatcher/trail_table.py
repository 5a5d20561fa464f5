"""The audit trail on AWS, as the dispatcher writes it: what it did by itself.

The trail's items and its append (one transaction of two conditional puts, chained again on
a lost race) are `vahr.protocol.audit`'s, shared with the skill; this module makes the
DynamoDB calls. The function's role may put items and read the trail's head, no more. A
record the trail cannot take is logged whole at ERROR and the task stands: the robot has
its command either way.
"""

from __future__ import annotations

import json
import logging
import random
import time
from typing import TYPE_CHECKING, Any

import boto3
import msgspec
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from vahr.protocol.audit import HEAD_KEY, append_chained, appended_items, head_from_item

if TYPE_CHECKING:
    from vahr.protocol.audit import AuditEntry, AuditRecord, TrailHead

log = logging.getLogger("dispatcher")

CLIENT_CONFIG = Config(connect_timeout=2.0, read_timeout=3.0, retries={"max_attempts": 2})


class TrailTable:
    """Appends the dispatcher's records to the audit table."""

    def __init__(self, table_name: str, client: Any = None) -> None:
        self.table_name = table_name
        self._client = client or boto3.client("dynamodb", config=CLIENT_CONFIG)

    def record(self, entry: AuditEntry) -> AuditRecord | None:
        """Append `entry`; None (and a log line holding it) when the trail cannot take it."""
        try:
            record = append_chained(entry, self._head, self._put, pause=_jitter)
        except (BotoCoreError, ClientError) as err:
            record, reason = None, str(err)
        else:
            reason = "the trail stayed busy"
        if record is None:
            log.error(
                json.dumps(
                    {
                        "event": "audit_unwritten",
                        "error": reason,
                        "record": msgspec.to_builtins(entry),
                    }
                )
            )
        return record

    def _head(self) -> TrailHead | None:
        answer = self._client.get_item(TableName=self.table_name, Key=HEAD_KEY, ConsistentRead=True)
        return head_from_item(answer.get("Item"))

    def _put(self, record: AuditRecord, head: TrailHead | None) -> bool:
        items = appended_items(record, head)
        for item in items:
            item["Put"]["TableName"] = self.table_name
        try:
            self._client.transact_write_items(TransactItems=items)
        except ClientError as err:
            if err.response.get("Error", {}).get("Code") == "TransactionCanceledException":
                return False
            raise
        return True


def _jitter(attempt: int) -> None:
    time.sleep(random.uniform(0, 0.02 * (attempt + 1)))  # noqa: S311 - jitter only
