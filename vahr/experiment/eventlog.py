"""The append-only, crash-safe event log of one experiment session (SQLite).

Every interaction (start and end of each utterance or click), command seen on the wire,
robot event, world change (arms, the LED) and observer input is one row, committed on its
own before `append` returns. The database runs in WAL mode with `synchronous=FULL`, so a
crash (or a pulled plug) loses nothing that `append` returned for, and triggers refuse any
UPDATE or DELETE of a logged event: corrections are new events, never edits.

Times are UTC with microseconds, taken from one clock (the logging machine's), so intervals
between a person's utterance and a robot's event are comparable. A robot's own timestamp is
kept inside the event's data.
"""

from __future__ import annotations

import json
import re
import sqlite3
import threading
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path
    from types import TracebackType

SCHEMA_VERSION = 1
SUFFIX = ".sqlite"
_PARTICIPANT = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,31}$")

_SCHEMA = """
CREATE TABLE IF NOT EXISTS events (
    seq  INTEGER PRIMARY KEY AUTOINCREMENT,
    at   TEXT NOT NULL,
    kind TEXT NOT NULL,
    task TEXT,
    data TEXT NOT NULL CHECK (json_valid(data))
);
CREATE TRIGGER IF NOT EXISTS events_append_only_update BEFORE UPDATE ON events
BEGIN SELECT RAISE(ABORT, 'the event log is append-only'); END;
CREATE TRIGGER IF NOT EXISTS events_append_only_delete BEFORE DELETE ON events
BEGIN SELECT RAISE(ABORT, 'the event log is append-only'); END;
"""


class Kind:
    """The kinds of logged events (the `kind` column)."""

    SESSION_STARTED = "session_started"  # participant, method, trial, seed, plan, simulated
    SESSION_RESUMED = "session_resumed"
    SESSION_ENDED = "session_ended"
    TASK_STARTED = "task_started"  # task
    TASK_ENDED = "task_ended"  # task, reason
    INTERACTION_STARTED = "interaction_started"  # id, channel (voice|click), text
    INTERACTION_ENDED = "interaction_ended"  # id, speech, intent, commands, error
    COMMAND = "command"  # a command seen on the wire: topic, id, action, params, source
    ROBOT_EVENT = "robot_event"  # an Event from vahr/robots/{thing}/events, as sent
    WORLD = "world"  # what, plus details: led on/off, package unloaded at a zone...
    OBSERVER = "observer"  # what (puzzle_piece), count, note
    TLX = "tlx"  # the questionnaire's eight levels


def now() -> datetime:
    return datetime.now(UTC)


def format_time(at: datetime) -> str:
    if at.tzinfo is None:
        raise ValueError("event times must carry a time zone")
    return at.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def parse_time(text: str) -> datetime:
    return datetime.fromisoformat(text).astimezone(UTC)


@dataclass(frozen=True)
class LogEntry:
    """One logged event."""

    seq: int
    at: datetime
    kind: str
    task: str | None
    data: dict[str, Any]

    def to_json(self) -> dict[str, Any]:
        return {
            "seq": self.seq,
            "at": format_time(self.at),
            "kind": self.kind,
            "task": self.task,
            "data": self.data,
        }


def session_name(participant: str, method: str, trial: int) -> str:
    """The file stem of a session: `P01-vahr-trial1`."""
    if not _PARTICIPANT.match(participant):
        raise VahrError(
            f"participant {participant!r} is not a valid id "
            "(1-32 letters, digits, '_' or '-', starting with a letter or digit)"
        )
    if trial < 1:
        raise VahrError(f"trial must be 1 or more, got {trial}")
    return f"{participant}-{method}-trial{trial}"


def session_file(log_dir: Path, participant: str, method: str, trial: int) -> Path:
    return log_dir / f"{session_name(participant, method, trial)}{SUFFIX}"


class EventLog:
    """One session's log file. Safe to append from several threads."""

    def __init__(self, path: Path, connection: sqlite3.Connection) -> None:
        self.path = path
        self._connection = connection
        self._lock = threading.Lock()

    @classmethod
    def open(cls, path: Path, *, create: bool = True) -> EventLog:
        """Open (and with `create`, make) the log at `path`; raise VahrError if it cannot."""
        if not create and not path.is_file():
            raise VahrError(f"no event log at {path}")
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            # isolation_level=None: autocommit; each append is its own transaction.
            connection = sqlite3.connect(path, isolation_level=None, check_same_thread=False)
            connection.execute("PRAGMA journal_mode=WAL")
            connection.execute("PRAGMA synchronous=FULL")
            version = connection.execute("PRAGMA user_version").fetchone()[0]
            if version not in (0, SCHEMA_VERSION):
                connection.close()
                raise VahrError(f"{path} is an event log of an unknown version {version}")
            connection.executescript(_SCHEMA)
            connection.execute(f"PRAGMA user_version={SCHEMA_VERSION}")
        except sqlite3.DatabaseError as err:
            raise VahrError(f"{path} is not a usable event log: {err}") from err
        return cls(path, connection)

    def append(
        self,
        kind: str,
        data: dict[str, Any] | None = None,
        *,
        task: str | None = None,
        at: datetime | None = None,
    ) -> LogEntry:
        """Log one event and commit it; returns the entry as stored."""
        when = at or now()
        body = json.dumps(data or {}, separators=(",", ":"), sort_keys=True, default=str)
        with self._lock:
            cursor = self._connection.execute(
                "INSERT INTO events (at, kind, task, data) VALUES (?, ?, ?, ?)",
                (format_time(when), kind, task, body),
            )
            seq = cursor.lastrowid
        assert seq is not None
        return LogEntry(
            seq=seq, at=parse_time(format_time(when)), kind=kind, task=task, data=json.loads(body)
        )

    def entries(self, kind: str | None = None, *, after: int = 0) -> list[LogEntry]:
        """Logged events in the order they were logged: optionally only of one kind, and only
        those after sequence number `after` (to follow the log as it grows)."""
        query = "SELECT seq, at, kind, task, data FROM events WHERE seq > ?"
        params: tuple[int | str, ...] = (after,)
        if kind is not None:
            query += " AND kind = ?"
            params = (after, kind)
        with self._lock:
            rows = self._connection.execute(query + " ORDER BY seq", params).fetchall()
        return [
            LogEntry(seq=seq, at=parse_time(at), kind=k, task=task, data=json.loads(data))
            for seq, at, k, task, data in rows
        ]

    def close(self) -> None:
        with self._lock:
            self._connection.close()

    def __enter__(self) -> EventLog:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


def read_log(path: Path) -> list[LogEntry]:
    """Every event of the log at `path` (which must exist)."""
    with EventLog.open(path, create=False) as log:
        return log.entries()


def find_logs(log_dir: Path) -> Iterator[Path]:
    """Every session log under `log_dir`, in name order."""
    if not log_dir.is_dir():
        raise VahrError(f"{log_dir} is not a directory of session logs")
    yield from sorted(log_dir.rglob(f"*{SUFFIX}"))
