"""One SQLite file shared by the threads of a process and by other processes: the local
stack's task queue and audit trail keep their state this way."""

from __future__ import annotations

import sqlite3
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

# How long a writer waits for another's lock before SQLite gives up, in seconds.
BUSY_TIMEOUT_S = 10.0


def open_shared(path: Path, schema: str) -> sqlite3.Connection:
    """A connection to `path` with `schema` applied. Autocommit mode: each transaction is
    opened explicitly with `BEGIN IMMEDIATE`, which takes the write lock at once, so a
    check and its update cannot interleave. WAL lets readers go on while one writes; its
    NORMAL sync is durable across a crash of the process (not of the machine)."""
    db = sqlite3.connect(
        path, check_same_thread=False, isolation_level=None, timeout=BUSY_TIMEOUT_S
    )
    db.execute("PRAGMA journal_mode=WAL")
    db.execute("PRAGMA synchronous=NORMAL")
    db.executescript(schema)
    return db
