"""The audit trail on AWS (DynamoDB under moto): records chained with conditional writes,
functions appending at once never forking the chain, and a table someone changed behind
the skill's back (an admin's writes) found by `verify`."""

from __future__ import annotations

import json
from typing import Any

import boto3
import pytest
from skill_testkit import REGION

from skill.audit_table import AuditTable
from tests.support.dynamodb_tables import create_audit_table
from vahr.protocol.audit import TRAIL_RECORDS as RECORDS
from vahr.protocol.audit import AuditEntry, verify

TABLE = "vahr-audit"


def entry(number: int) -> AuditEntry:
    return AuditEntry(
        time="2026-11-28T10:00:00.000Z",
        who="amzn1.ask.account.SUSAN",
        channel="alexa",
        intent="NavigateIntent",
        slots={"zone": "A"},
        robots=["placebot1"],
        commands=[f"c-{number}"],
        outcome="sent",
    )


@pytest.fixture
def client(aws: None) -> Any:
    dynamodb = boto3.client("dynamodb", region_name=REGION)
    create_audit_table(dynamodb, TABLE)
    return dynamodb


@pytest.fixture
def table(client: Any) -> AuditTable:
    trail = AuditTable(TABLE, client)
    for number in range(1, 5):
        trail.append(entry(number))
    return trail


def item(client: Any, seq: int) -> dict[str, Any]:
    found: dict[str, Any] = client.get_item(
        TableName=TABLE, Key={"trail": {"S": RECORDS}, "seq": {"N": str(seq)}}
    )["Item"]
    return found


def test_appended_records_are_chained_with_a_head(table: AuditTable) -> None:
    records = table.records()
    assert [r.seq for r in records] == [1, 2, 3, 4]
    assert table.head() is not None and table.head().seq == 4  # type: ignore[union-attr]
    assert verify(records, table.head()) == []


def test_two_functions_appending_at_once_never_fork_the_chain(client: Any) -> None:
    # Given two functions that both read the head before either wrote
    first, second = AuditTable(TABLE, client), AuditTable(TABLE, client)
    first.append(entry(1))
    real_head = second.head
    reads = []

    def stale_once() -> Any:
        head = real_head()
        reads.append(head)
        if len(reads) == 1:
            first.append(entry(2))  # the other function wins the race meanwhile
        return head

    second.head = stale_once  # type: ignore[method-assign]
    # When the second appends on the head it read, its transaction loses and it chains again
    record = second.append(entry(3))
    # Then the trail has three records in one chain, none overwritten
    assert record.seq == 3 and [head.seq for head in reads] == [1, 2]
    records = first.records()
    assert [r.commands for r in records] == [["c-1"], ["c-2"], ["c-3"]]
    assert verify(records, first.head()) == []


def test_an_edited_record_is_found(table: AuditTable, client: Any) -> None:
    stored = item(client, 2)
    edited = json.loads(stored["record"]["S"]) | {"outcome": "refused"}
    client.put_item(TableName=TABLE, Item={**stored, "record": {"S": json.dumps(edited)}})
    faults = [str(f) for f in verify(table.records(), table.head())]
    assert faults == ["record 2: its content does not match its hash (altered)"]


def test_a_deleted_record_is_found(table: AuditTable, client: Any) -> None:
    client.delete_item(TableName=TABLE, Key={"trail": {"S": RECORDS}, "seq": {"N": "3"}})
    faults = [str(f) for f in verify(table.records(), table.head())]
    assert faults == ["record 4: record 3 before it is missing (removed)"]


def test_a_reordered_record_is_found(table: AuditTable, client: Any) -> None:
    second, third = item(client, 2), item(client, 3)
    client.put_item(TableName=TABLE, Item={**second, "record": third["record"]})
    client.put_item(TableName=TABLE, Item={**third, "record": second["record"]})
    faults = verify(table.records(), table.head())
    assert {f.seq for f in faults} >= {2, 3}


def test_the_last_record_deleted_is_found_by_the_head(table: AuditTable, client: Any) -> None:
    client.delete_item(TableName=TABLE, Key={"trail": {"S": RECORDS}, "seq": {"N": "4"}})
    faults = [str(f) for f in verify(table.records(), table.head())]
    assert faults == ["record 4: the trail ends at record 3; the last are missing"]
