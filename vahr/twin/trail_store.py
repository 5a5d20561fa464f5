"""The audit trail on one machine: the twin of the DynamoDB audit table, in SQLite.

`audit.sqlite3` in the state directory holds one row per record (`seq`, and the record as
JSON, `vahr.protocol.audit`) and the trail's head (the last record's number and hash) in a
table of its own. Appending reads the head, chains the entry to it and writes both in one
`BEGIN IMMEDIATE` transaction, so appends from threads (or processes sharing the file)
never fork the chain. Triggers refuse any UPDATE or DELETE of a record: the trail only
grows. Someone with the file can still drop them and edit it; `verify` then finds the
record edited, removed or moved (the row's `seq` wins over the number in its JSON, so a
record moved to another number reads as altered).

The data plane serves it (`TrailApi`): `POST /vahr/audit` appends an entry (every local
host, the station and the skill write through it), `GET /vahr/audit?after=N&limit=M`
reads a page of records with the head.
"""

from __future__ import annotations

import threading
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.plumbing.sqlite_file import open_shared
from vahr.protocol import ProtocolError
from vahr.protocol.audit import (
    AuditEntry,
    AuditRecord,
    TrailHead,
    chained,
    entry_from_builtins,
    record_from_json,
)

if TYPE_CHECKING:
    import sqlite3
    from collections.abc import Iterator

FILE_NAME = "audit.sqlite3"
AUDIT_PATH = "/vahr/audit"
PAGE_DEFAULT = 100
PAGE_MAX = 1000

_SCHEMA = """
CREATE TABLE IF NOT EXISTS records (seq INTEGER PRIMARY KEY, record TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS head (
    id INTEGER PRIMARY KEY CHECK (id = 0),
    seq INTEGER NOT NULL,
    hash TEXT NOT NULL
);
CREATE TRIGGER IF NOT EXISTS records_never_change BEFORE UPDATE ON records
BEGIN SELECT RAISE(ABORT, 'the audit trail is append-only'); END;
CREATE TRIGGER IF NOT EXISTS records_never_go BEFORE DELETE ON records
BEGIN SELECT RAISE(ABORT, 'the audit trail is append-only'); END;
"""


class SqliteTrail:
    """The trail in one SQLite file; safe to share between threads."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        self._db = open_shared(self.path, _SCHEMA)
        self._lock = threading.Lock()

    @classmethod
    def in_state_dir(cls, state_dir: Path) -> SqliteTrail:
        state_dir.mkdir(parents=True, exist_ok=True)
        return cls(state_dir / FILE_NAME)

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        with self._lock:
            self._db.execute("BEGIN IMMEDIATE")
            try:
                yield self._db
            except BaseException:
                self._db.execute("ROLLBACK")
                raise
            self._db.execute("COMMIT")

    def append(self, entry: AuditEntry) -> AuditRecord:
        """Number and chain `entry` after the trail's last record, and store it."""
        with self._transaction() as db:
            row = db.execute("SELECT seq, hash FROM head WHERE id = 0").fetchone()
            record = chained(entry, TrailHead(row[0], row[1]) if row else None)
            db.execute(
                "INSERT INTO records (seq, record) VALUES (?, ?)",
                (record.seq, msgspec.json.encode(record).decode()),
            )
            db.execute(
                "INSERT INTO head (id, seq, hash) VALUES (0, ?, ?) "
                "ON CONFLICT (id) DO UPDATE SET seq = excluded.seq, hash = excluded.hash",
                (record.seq, record.hash),
            )
        return record

    def head(self) -> TrailHead | None:
        with self._lock:
            row = self._db.execute("SELECT seq, hash FROM head WHERE id = 0").fetchone()
        return TrailHead(row[0], row[1]) if row else None

    def records(self, after: int = 0, limit: int | None = None) -> list[AuditRecord]:
        """The records numbered above `after`, in order, at most `limit` of them."""
        query = "SELECT seq, record FROM records WHERE seq > ? ORDER BY seq"
        params: tuple[int, ...] = (after,)
        if limit is not None:
            query += " LIMIT ?"
            params = (after, limit)
        with self._lock:
            rows = self._db.execute(query, params).fetchall()
        return [_stored(seq, text) for seq, text in rows]

    def snapshot(self, after: int, limit: int) -> tuple[list[AuditRecord], TrailHead | None]:
        """Up to `limit` records above `after` and the head, read together (the head is
        never older than the records beside it)."""
        with self._lock:
            rows = self._db.execute(
                "SELECT seq, record FROM records WHERE seq > ? ORDER BY seq LIMIT ?",
                (after, limit),
            ).fetchall()
            row = self._db.execute("SELECT seq, hash FROM head WHERE id = 0").fetchone()
        return [_stored(seq, text) for seq, text in rows], (TrailHead(*row) if row else None)

    def close(self) -> None:
        with self._lock:
            self._db.close()


def _stored(seq: int, text: str) -> AuditRecord:
    record = record_from_json(text)
    return record if record.seq == seq else msgspec.structs.replace(record, seq=seq)


class TrailApi:
    """`/vahr/audit` on the data plane, as two local routes."""

    def __init__(self, trail: SqliteTrail) -> None:
        self.trail = trail

    def append(self, request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        try:
            entry = entry_from_builtins(request)
        except ProtocolError as err:
            return 400, {"code": 400, "message": str(err)}
        return 200, msgspec.to_builtins(self.trail.append(entry))

    def page(self, request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        """`{"records": [...], "head": {"seq", "hash"} | null, "next": N | null}`: `next` is
        the `after` of the following page, null on the last."""
        try:
            after = int(request.get("after", 0))
            limit = int(request.get("limit", PAGE_DEFAULT))
        except (TypeError, ValueError):
            return 400, {"code": 400, "message": "after and limit must be whole numbers"}
        if after < 0 or not 1 <= limit <= PAGE_MAX:
            return 400, {
                "code": 400,
                "message": f"after must be 0 or more and limit 1 to {PAGE_MAX}",
            }
        records, head = self.trail.snapshot(after, limit + 1)
        more = len(records) > limit
        records = records[:limit]
        return 200, {
            "records": msgspec.to_builtins(records),
            "head": msgspec.to_builtins(head) if head is not None else None,
            "next": records[-1].seq if more else None,
        }
