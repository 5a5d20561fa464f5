"""The session log: append-only, every event committed, readable after a crash."""

from __future__ import annotations

import sqlite3
import subprocess
import sys
import textwrap
from typing import TYPE_CHECKING

import pytest

from vahr.errors import VahrError
from vahr.experiment.eventlog import EventLog, Kind, read_log, session_file

if TYPE_CHECKING:
    from pathlib import Path


def test_events_come_back_in_order_with_their_data(tmp_path: Path) -> None:
    path = tmp_path / "log.sqlite"
    with EventLog.open(path) as log:
        log.append(Kind.TASK_STARTED, {"task": "I"}, task="I")
        log.append(Kind.OBSERVER, {"what": "puzzle_piece", "count": 2}, task="I")
    entries = read_log(path)
    assert [e.kind for e in entries] == ["task_started", "observer"]
    assert entries[1].data == {"what": "puzzle_piece", "count": 2}
    assert entries[0].at <= entries[1].at
    assert entries[0].task == "I"


def test_logged_events_cannot_be_edited_or_deleted(tmp_path: Path) -> None:
    path = tmp_path / "log.sqlite"
    with EventLog.open(path) as log:
        log.append(Kind.OBSERVER, {"what": "puzzle_piece"})
    connection = sqlite3.connect(path)
    with pytest.raises(sqlite3.IntegrityError, match="append-only"):
        connection.execute("UPDATE events SET kind = 'x'")
    with pytest.raises(sqlite3.IntegrityError, match="append-only"):
        connection.execute("DELETE FROM events")
    connection.close()
    assert len(read_log(path)) == 1


def test_the_log_uses_wal_so_a_crash_loses_nothing_committed(tmp_path: Path) -> None:
    # Given a process that logs events and is then killed without closing the log
    path = tmp_path / "log.sqlite"
    code = textwrap.dedent(f"""
        import os
        from pathlib import Path
        from vahr.experiment.eventlog import EventLog
        log = EventLog.open(Path({str(path)!r}))
        for n in range(50):
            log.append("observer", {{"what": "puzzle_piece", "n": n}})
        os._exit(9)  # no close, no flush: a crash
    """)
    result = subprocess.run([sys.executable, "-c", code], timeout=60, check=False)
    assert result.returncode == 9
    # When the log is opened again
    with EventLog.open(path) as log:
        mode = log._connection.execute("PRAGMA journal_mode").fetchone()[0]
        entries = log.entries()
        # Then every event that append returned for is there, and appending goes on
        log.append(Kind.SESSION_RESUMED)
    assert mode == "wal"
    assert [e.data["n"] for e in entries] == list(range(50))
    assert read_log(path)[-1].kind == "session_resumed"


def test_a_file_that_is_not_a_log_is_named_in_the_error(tmp_path: Path) -> None:
    path = tmp_path / "notes.sqlite"
    path.write_text("hello, this is not a database" * 100)
    with pytest.raises(VahrError, match="not a usable event log"):
        EventLog.open(path)
    with pytest.raises(VahrError, match="no event log at"):
        EventLog.open(tmp_path / "missing.sqlite", create=False)


def test_session_files_are_named_by_participant_method_and_trial(tmp_path: Path) -> None:
    assert session_file(tmp_path, "P07", "keyboard", 2).name == "P07-keyboard-trial2.sqlite"
    with pytest.raises(VahrError, match="not a valid id"):
        session_file(tmp_path, "../etc", "vahr", 1)
    with pytest.raises(VahrError, match="trial must be 1 or more"):
        session_file(tmp_path, "P1", "vahr", 0)
