"""The audit record's hash chain (pure): anyone can recompute a record's hash, and `verify`
finds a record edited, removed or moved."""

from __future__ import annotations

import hashlib
import json

import msgspec
import pytest

from vahr.protocol.audit import GENESIS, AuditEntry, TrailHead, chained, record_hash, verify


def entry(words: str, outcome: str = "sent") -> AuditEntry:
    return AuditEntry(
        time="2026-11-28T10:00:00.000Z",
        who="amzn1.ask.account.SUSAN",
        name="Susan",
        role="supervisor",
        channel="alexa",
        words=words,
        intent="NavigateIntent",
        slots={"robot": "all", "zone": "A"},
        robots=["placebot1", "placebot2"],
        commands=["c-1"],
        outcome=outcome,  # type: ignore[arg-type]
    )


def trail(count: int) -> list:  # type: ignore[type-arg]
    records, head = [], None
    for number in range(count):
        record = chained(entry(f"send all robots to zone {number}"), head)
        records.append(record)
        head = TrailHead(record.seq, record.hash)
    return records


def test_a_records_hash_is_the_sha256_of_its_canonical_json() -> None:
    [record] = trail(1)
    fields = msgspec.to_builtins(record)
    del fields["hash"]
    canonical = json.dumps(fields, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    assert record.hash == hashlib.sha256(canonical.encode()).hexdigest()
    assert record.prev == GENESIS and record.seq == 1
    assert record_hash(msgspec.to_builtins(record)) == record.hash


def test_an_intact_trail_verifies() -> None:
    records = trail(4)
    assert verify(records, TrailHead(4, records[-1].hash)) == []
    assert verify([], None) == []


def test_an_edited_record_is_found() -> None:
    records = trail(4)
    records[1] = msgspec.structs.replace(records[1], outcome="refused")
    [fault] = verify(records, TrailHead(4, records[-1].hash))
    assert str(fault) == "record 2: its content does not match its hash (altered)"


def test_a_removed_record_is_found() -> None:
    records = trail(4)
    del records[2]
    [fault] = verify(records, TrailHead(4, records[-1].hash))
    assert str(fault) == "record 4: record 3 before it is missing (removed)"


def test_the_last_records_removed_are_found_by_the_head() -> None:
    records = trail(4)
    head = TrailHead(4, records[-1].hash)
    [fault] = verify(records[:2], head)
    assert str(fault) == "record 4: the trail ends at record 2; the last are missing"


@pytest.mark.parametrize("recomputed", [False, True])
def test_two_records_swapped_are_found(recomputed: bool) -> None:
    records = trail(4)
    # Their places swapped: each renumbered (and, by a careful forger, rehashed)
    second, third = records[1], records[2]
    moved = [
        msgspec.structs.replace(third, seq=2),
        msgspec.structs.replace(second, seq=3),
    ]
    if recomputed:
        moved = [
            msgspec.structs.replace(m, hash=record_hash(msgspec.to_builtins(m))) for m in moved
        ]
    faults = verify([records[0], *moved, records[3]], TrailHead(4, records[-1].hash))
    assert faults, "a reordered trail must not verify"
    reasons = {fault.reason for fault in faults}
    assert (
        "it does not follow the record before it (removed or reordered)" in reasons
        if recomputed
        else "its content does not match its hash (altered)" in reasons
    )
