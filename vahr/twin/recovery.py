"""What an earlier run left on a state directory, found and put right at start.

A stack holds `STATE_DIR/vahr.pid` locked while it runs (the kernel drops the lock when the
process dies, however it dies) and empties it when it stops cleanly. At the next start:

- the lock held by a live process means the directory is in use: a one-line error;
- a pid left in the file means the run before did not stop cleanly;
- processes whose environment says they were started for this directory
  (`VAHR_STARTED_FOR`, see `lifetime`) and are still running are stopped, since they
  hold its ports and files (a broker of an older version, or one that survived somehow);
- a write-ahead log or journal next to the shadow database means its last writer died
  mid-session: SQLite replays it, and a database that fails its integrity check is moved
  aside rather than served.

`recover()` does all of it and returns one line saying what was done (None if nothing).
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import select
import signal
import sqlite3
import time
from dataclasses import dataclass
from pathlib import Path

from vahr.errors import VahrError
from vahr.plumbing.lifetime import STARTED_FOR

LOCK_FILE = "vahr.pid"
STOP_TIMEOUT_S = 2.0


class StateLock:
    """An exclusive, crash-safe claim on a state directory (an flock'ed pid file)."""

    def __init__(self, state_dir: Path) -> None:
        self.path = state_dir / LOCK_FILE
        self._fd: int | None = None

    def acquire(self) -> int | None:
        """Claim the directory; return the pid of a run that held it and did not stop
        cleanly, or None. Raise VahrError if a live process holds it."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _read_pid(fd)
            os.close(fd)
            raise VahrError(
                f"the state directory {self.path.parent} is in use by another run"
                f"{f' (pid {holder})' if holder else ''}; stop it or pass another --state-dir"
            ) from None
        earlier = _read_pid(fd)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd
        return earlier if earlier and earlier != os.getpid() else None

    def release(self) -> None:
        """Mark a clean stop (an empty file) and drop the claim; safe to call twice."""
        fd, self._fd = self._fd, None
        if fd is None:
            return
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
        os.close(fd)


def _read_pid(fd: int) -> int | None:
    text = os.pread(fd, 32, 0).decode(errors="replace").strip()
    return int(text) if text.isdigit() else None


@dataclass(frozen=True)
class Leftover:
    """A process started for a state directory that is still running."""

    pid: int
    name: str

    def __str__(self) -> str:
        return f"{self.name} (pid {self.pid})"


def started_for(state_dir: Path) -> list[Leftover]:
    """Live processes (of this user) started for `state_dir` or a directory inside it."""
    root = str(state_dir)
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            environ = (entry / "environ").read_bytes().split(b"\0")
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
            argv = (entry / "cmdline").read_bytes().split(b"\0")
        except (OSError, IndexError):
            continue  # gone, or not ours to read
        if state == "Z":
            continue
        for variable in environ:
            name, _, value = variable.decode(errors="replace").partition("=")
            if name == STARTED_FOR and (value == root or value.startswith(root + os.sep)):
                found.append(Leftover(int(entry.name), _program(argv)))
                break
    return sorted(found, key=lambda leftover: leftover.pid)


def _program(argv: list[bytes]) -> str:
    words = [a.decode(errors="replace") for a in argv if a]
    for module in ("robot_agent.cli", "vahr.cli"):
        if module in words:
            return module.split(".")[0].replace("_", "-")
    return Path(words[0]).name if words else "process"


def stop_all(leftovers: list[Leftover], timeout_s: float = STOP_TIMEOUT_S) -> list[Leftover]:
    """SIGTERM each, wait up to `timeout_s`, SIGKILL the rest; return those still alive.

    Each process is held by a pidfd while it is signalled, so a pid reused in between
    is never hit.
    """
    handles: dict[int, Leftover] = {}
    for leftover in leftovers:
        with contextlib.suppress(OSError):
            fd = os.pidfd_open(leftover.pid)
            handles[fd] = leftover
            signal.pidfd_send_signal(fd, signal.SIGTERM)
    try:
        _wait_exited(handles, timeout_s)
        for fd in list(handles):
            with contextlib.suppress(OSError):
                signal.pidfd_send_signal(fd, signal.SIGKILL)
        _wait_exited(handles, timeout_s)
        return list(handles.values())
    finally:
        for fd in handles:
            os.close(fd)


def _wait_exited(handles: dict[int, Leftover], timeout_s: float) -> None:
    """Drop from `handles` each process that exits within `timeout_s` (pidfd readable)."""
    deadline = time.monotonic() + timeout_s
    while handles:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            return
        ready, _, _ = select.select(list(handles), [], [], remaining)
        for fd in ready:
            handles.pop(fd)
            os.close(fd)


def recover_database(database: Path) -> str | None:
    """Replay (or move aside) what a crash left next to a SQLite database; say what."""
    leftovers = [
        path
        for path in (database.with_name(database.name + s) for s in ("-wal", "-journal"))
        if path.exists() and path.stat().st_size > 0
    ]
    if not database.exists() and not leftovers:
        return None
    size = sum(path.stat().st_size for path in leftovers)
    healthy = True
    try:
        with contextlib.closing(sqlite3.connect(database, isolation_level=None)) as db:
            healthy = db.execute("PRAGMA integrity_check").fetchone() == ("ok",)
            if healthy and leftovers:
                db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    except sqlite3.DatabaseError:
        healthy = False
    if not healthy:
        aside = database.with_name(f"{database.name}.damaged-{time.strftime('%Y%m%d-%H%M%S')}")
        for suffix in ("", "-wal", "-shm", "-journal"):
            part = database.with_name(database.name + suffix)
            if part.exists():
                part.replace(aside.with_name(aside.name + suffix))
        return f"the shadow database was damaged; moved it to {aside.name} and started empty"
    if leftovers:
        kind = "write-ahead log" if leftovers[0].name.endswith("-wal") else "journal"
        return f"replayed the shadow database's unfinished {kind} ({size} bytes)"
    return None


def recover(state_dir: Path, *, unclean_pid: int | None, database: Path) -> str | None:
    """Stop leftovers and repair the shadow database; one line saying what was done."""
    done: list[str] = []
    if unclean_pid is not None:
        done.append(f"the run before (pid {unclean_pid}) did not stop cleanly")
    leftovers = started_for(state_dir)
    if leftovers:
        survivors = stop_all(leftovers)
        if survivors:
            raise VahrError(
                f"processes left by an earlier run on {state_dir} would not stop: "
                f"{', '.join(map(str, survivors))}"
            )
        done.append(f"stopped what it left running: {', '.join(map(str, leftovers))}")
    database_note = recover_database(database)
    if database_note:
        done.append(database_note)
    return "; ".join(done) if done else None


__all__ = ["Leftover", "StateLock", "recover", "recover_database", "started_for", "stop_all"]
