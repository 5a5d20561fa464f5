"""The local audit trail in SQLite: append-only, chained, and a trail someone edited behind
its back (triggers dropped, rows changed) found by `verify`."""

from __future__ import annotations

import json
import sqlite3
import threading
from typing import TYPE_CHECKING

import pytest

from vahr.protocol.audit import AuditEntry, verify
from vahr.twin.trail_store import SqliteTrail, TrailApi

if TYPE_CHECKING:
    from pathlib import Path


def entry(number: int) -> AuditEntry:
    return AuditEntry(
        time="2026-11-28T10:00:00.000Z",
        who="amzn1.ask.account.OTTO",
        name="Otto",
        role="operator",
        channel="station-panel",
        words=f"navigate placebot1 to {number}",
        robots=["placebot1"],
        commands=[f"c-{number}"],
        outcome="sent",
    )


@pytest.fixture
def trail(tmp_path: Path) -> SqliteTrail:
    store = SqliteTrail.in_state_dir(tmp_path)
    for number in range(1, 6):
        store.append(entry(number))
    yield store
    store.close()


def tamper(trail: SqliteTrail, *statements: str) -> None:
    """What someone with the file could do: drop the triggers and change rows."""
    db = sqlite3.connect(trail.path)
    db.execute("DROP TRIGGER records_never_change")
    db.execute("DROP TRIGGER records_never_go")
    for statement in statements:
        db.execute(statement)
    db.commit()
    db.close()


def test_records_are_numbered_and_chained(trail: SqliteTrail) -> None:
    records = trail.records()
    assert [r.seq for r in records] == [1, 2, 3, 4, 5]
    assert [r.prev for r in records[1:]] == [r.hash for r in records[:-1]]
    assert verify(records, trail.head()) == []


def test_the_database_refuses_changes_to_a_record(trail: SqliteTrail) -> None:
    db = sqlite3.connect(trail.path)
    with pytest.raises(sqlite3.DatabaseError, match="append-only"):
        db.execute("UPDATE records SET record = '{}' WHERE seq = 2")
    with pytest.raises(sqlite3.DatabaseError, match="append-only"):
        db.execute("DELETE FROM records WHERE seq = 2")
    db.close()
    assert verify(trail.records(), trail.head()) == []


def test_an_edited_record_is_found(trail: SqliteTrail) -> None:
    [(text,)] = sqlite3.connect(trail.path).execute("SELECT record FROM records WHERE seq = 3")
    edited = json.loads(text) | {"who": "amzn1.ask.account.SOMEONEELSE"}
    tamper(trail, f"UPDATE records SET record = '{json.dumps(edited)}' WHERE seq = 3")
    faults = [str(f) for f in verify(trail.records(), trail.head())]
    assert faults == ["record 3: its content does not match its hash (altered)"]


def test_a_deleted_record_is_found(trail: SqliteTrail) -> None:
    tamper(trail, "DELETE FROM records WHERE seq = 2")
    faults = [str(f) for f in verify(trail.records(), trail.head())]
    assert faults == ["record 3: record 2 before it is missing (removed)"]


def test_the_last_record_deleted_is_found(trail: SqliteTrail) -> None:
    tamper(trail, "DELETE FROM records WHERE seq = 5")
    faults = [str(f) for f in verify(trail.records(), trail.head())]
    assert faults == ["record 5: the trail ends at record 4; the last are missing"]


def test_reordered_records_are_found(trail: SqliteTrail) -> None:
    # Rows 2 and 4 swap places: each now sits at the other's number
    tamper(
        trail,
        "UPDATE records SET seq = -2 WHERE seq = 2",
        "UPDATE records SET seq = 2 WHERE seq = 4",
        "UPDATE records SET seq = 4 WHERE seq = -2",
    )
    faults = verify(trail.records(), trail.head())
    assert {f.seq for f in faults} >= {2, 4}
    assert all("altered" in f.reason or "reordered" in f.reason for f in faults)


def test_appends_from_many_threads_never_fork_the_chain(tmp_path: Path) -> None:
    store = SqliteTrail.in_state_dir(tmp_path / "many")
    threads = [
        threading.Thread(target=lambda n=n: [store.append(entry(n * 10 + i)) for i in range(10)])
        for n in range(4)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(10)
    records = store.records()
    assert len(records) == 40
    assert verify(records, store.head()) == []
    store.close()


def test_the_api_pages_the_trail_with_its_head(trail: SqliteTrail) -> None:
    api = TrailApi(trail)
    status, first = api.page({"limit": "2"})
    assert status == 200 and [r["seq"] for r in first["records"]] == [1, 2]
    assert first["next"] == 2 and first["head"]["seq"] == 5
    _, last = api.page({"after": "4", "limit": "2"})
    assert [r["seq"] for r in last["records"]] == [5] and last["next"] is None
    assert api.page({"limit": "0"})[0] == 400
    assert api.page({"after": "x"})[0] == 400


def test_the_api_appends_an_entry_and_refuses_a_malformed_one(trail: SqliteTrail) -> None:
    api = TrailApi(trail)
    sent = {"time": "2026-11-28T10:00:00.000Z", "who": "api", "channel": "api", "outcome": "sent"}
    status, record = api.append(sent)
    assert status == 200 and record["seq"] == 6
    status, refused = api.append({"who": "api", "channel": "api", "outcome": "moved"})
    assert status == 400 and refused["message"].startswith(("outcome", "time"))
    assert len(trail.records()) == 6
