"""The local stack's fleet task queue: `vahr.dispatch.TaskStore` over SQLite.

One row per task, in `tasks.sqlite3` in the state directory, so the queue and who holds
which task survive a restart of `vahr up`; the zones closed at run time are rows of their
own table in the same file, and so are the robots taken out of service. Every conditional
change is one SQL statement (an UPDATE whose WHERE is the condition) inside one
`BEGIN IMMEDIATE` transaction, so two dispatchers, in threads or in processes sharing the
file, cannot give one task to two robots or two tasks to one robot: the loser's UPDATE
changes no row and it gets None.
"""

from __future__ import annotations

import threading
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

from vahr.dispatch import Outcome, Task
from vahr.plumbing.sqlite_file import open_shared

if TYPE_CHECKING:
    import sqlite3
    from collections.abc import Iterator

FILE_NAME = "tasks.sqlite3"

# `document` is the task as JSON; the columns beside it are what the conditions and the
# queue's order read. The partial unique index is the rule "one active task per robot"
# written where SQLite itself enforces it.
_SCHEMA = """
CREATE TABLE IF NOT EXISTS tasks (
    id TEXT PRIMARY KEY,
    status TEXT NOT NULL,
    thing TEXT,
    created_at TEXT NOT NULL,
    document BLOB NOT NULL
);
CREATE INDEX IF NOT EXISTS tasks_by_status ON tasks (status, created_at, id);
CREATE UNIQUE INDEX IF NOT EXISTS one_task_per_robot ON tasks (thing) WHERE status = 'assigned';
CREATE TABLE IF NOT EXISTS closed_zones (
    zone TEXT PRIMARY KEY,
    closed_at TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS out_of_service (
    thing TEXT PRIMARY KEY,
    since TEXT NOT NULL
);
"""

_decoder = msgspec.json.Decoder(Task)


class SqliteTaskStore:
    """Tasks in one SQLite file; safe to share between threads and between processes."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        self._db = open_shared(self.path, _SCHEMA)
        self._lock = threading.Lock()

    @classmethod
    def in_state_dir(cls, state_dir: Path) -> SqliteTaskStore:
        return cls(Path(state_dir) / FILE_NAME)

    def close(self) -> None:
        with self._lock:
            self._db.close()

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

    def _load(self, db: sqlite3.Connection, task_id: str) -> Task | None:
        row = db.execute("SELECT document FROM tasks WHERE id = ?", (task_id,)).fetchone()
        return None if row is None else _decoder.decode(row[0])

    @staticmethod
    def _save(db: sqlite3.Connection, task: Task) -> None:
        db.execute(
            "UPDATE tasks SET status = ?, thing = ?, document = ? WHERE id = ?",
            (task.status, task.thing, msgspec.json.encode(task), task.id),
        )

    # --- the TaskStore port ---------------------------------------------------------------

    def add(self, task: Task) -> None:
        with self._transaction() as db:
            db.execute(
                "INSERT INTO tasks (id, status, thing, created_at, document) VALUES (?,?,?,?,?)",
                (task.id, task.status, task.thing, task.created_at, msgspec.json.encode(task)),
            )

    def assign(self, task_id: str, thing: str, *, at: str) -> Task | None:
        with self._transaction() as db:
            task = self._load(db, task_id)
            if task is None or task.status != "queued":
                return None
            busy = db.execute(
                "SELECT 1 FROM tasks WHERE thing = ? AND status = 'assigned'", (thing,)
            ).fetchone()
            if busy is not None:
                return None
            taken = task.assigned(thing, at=at)
            self._save(db, taken)
            return taken

    def release(self, task_id: str) -> Task | None:
        with self._transaction() as db:
            task = self._load(db, task_id)
            if task is None or task.status != "assigned":
                return None
            back = task.released()
            self._save(db, back)
            return back

    def finish(self, task_id: str, *, outcome: Outcome) -> Task | None:
        with self._transaction() as db:
            task = self._load(db, task_id)
            if task is None or task.status != "assigned":
                return None
            ended = task.finished(outcome)
            self._save(db, ended)
            return ended

    def cancel(self, task_id: str) -> Task | None:
        with self._transaction() as db:
            task = self._load(db, task_id)
            if task is None or not task.is_open:
                return None
            self._save(db, task.cancelled())
            return task

    def get(self, task_id: str) -> Task | None:
        with self._lock:
            return self._load(self._db, task_id)

    def pending(self) -> list[Task]:
        return self._with_status("queued")

    def active(self) -> list[Task]:
        tasks = self._with_status("assigned")
        return sorted(tasks, key=lambda task: (task.assigned_at or "", task.id))

    def close_zone(self, zone: str, *, at: str) -> bool:
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT OR IGNORE INTO closed_zones (zone, closed_at) VALUES (?, ?)", (zone, at)
            )
            return cursor.rowcount == 1

    def open_zone(self, zone: str) -> bool:
        with self._transaction() as db:
            return db.execute("DELETE FROM closed_zones WHERE zone = ?", (zone,)).rowcount == 1

    def closed_zones(self) -> list[str]:
        with self._lock:
            rows = self._db.execute("SELECT zone FROM closed_zones ORDER BY zone").fetchall()
        return [row[0] for row in rows]

    # --- robots out of service (the local host's; the dispatcher reads `in_service`) ----

    def set_in_service(self, thing: str, in_service: bool, *, at: str) -> bool:
        """Record `thing` in service or out of it (since `at`); False when it already was."""
        with self._transaction() as db:
            if in_service:
                return (
                    db.execute("DELETE FROM out_of_service WHERE thing = ?", (thing,)).rowcount == 1
                )
            cursor = db.execute(
                "INSERT OR IGNORE INTO out_of_service (thing, since) VALUES (?, ?)", (thing, at)
            )
            return cursor.rowcount == 1

    def out_of_service(self) -> list[str]:
        """The robots out of service now, sorted."""
        with self._lock:
            rows = self._db.execute("SELECT thing FROM out_of_service ORDER BY thing").fetchall()
        return [row[0] for row in rows]

    def _with_status(self, status: str) -> list[Task]:
        with self._lock:
            rows = self._db.execute(
                "SELECT document FROM tasks WHERE status = ? ORDER BY created_at, id", (status,)
            ).fetchall()
        return [_decoder.decode(row[0]) for row in rows]
