"""Child processes that cannot outlive the process that started them.

`spawn()` is `subprocess.Popen` for the long-running children of the lab side (mosquitto,
robot-agents). Each child starts through `lifeline.py`, which arms Linux's parent-death
signal and then execs the real command, so the child is signalled the moment its parent
dies, however it dies: Ctrl-C, an exception, or SIGKILL, which no handler can catch.

The kernel sends the parent-death signal when the *thread* that forked the child ends, not
when the process does. A child forked from a short-lived worker thread would be killed when
that thread returns, so every child is forked by one daemon thread that lives exactly as
long as the process (the spawner); callers on any thread hand it their request.

Every child also carries `VAHR_STARTED_FOR=<its state directory>` in its environment (and
passes it on to its own children), so the next start on the same state directory can find
and stop whatever an earlier crash left behind (`vahr.twin.recovery`).
"""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import threading
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any

from vahr.lifeline import lifeline_command

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from pathlib import Path

STARTED_FOR = "VAHR_STARTED_FOR"
SPAWN_TIMEOUT_S = 30.0

_Request = tuple["Callable[[], subprocess.Popen[Any]]", "Future[subprocess.Popen[Any]]"]


class _Spawner:
    """The one thread that forks every child; started on first use, once per process."""

    def __init__(self) -> None:
        self._requests: queue.SimpleQueue[_Request] = queue.SimpleQueue()
        self._thread: threading.Thread | None = None
        self._pid = 0
        self._lock = threading.Lock()

    def run(self, start: Callable[[], subprocess.Popen[Any]]) -> subprocess.Popen[Any]:
        thread = self._ensure_thread()
        if threading.current_thread() is thread:
            return start()
        future: Future[subprocess.Popen[Any]] = Future()
        self._requests.put((start, future))
        return future.result(timeout=SPAWN_TIMEOUT_S)

    def _ensure_thread(self) -> threading.Thread:
        with self._lock:
            # After os.fork() the child has no spawner thread of its own: start a new one.
            if self._thread is None or self._pid != os.getpid() or not self._thread.is_alive():
                self._requests = queue.SimpleQueue()
                self._pid = os.getpid()
                self._thread = threading.Thread(
                    target=self._serve, args=(self._requests,), name="vahr-spawner", daemon=True
                )
                self._thread.start()
            return self._thread

    @staticmethod
    def _serve(requests: queue.SimpleQueue[_Request]) -> None:
        # Never returns: its end would signal every child it started.
        while True:
            start, future = requests.get()
            if not future.set_running_or_notify_cancel():
                continue
            try:
                future.set_result(start())
            except BaseException as err:  # handed to the caller, who raises it
                future.set_exception(err)


_spawner = _Spawner()


def spawn(
    command: Sequence[str],
    *,
    started_for: Path,
    death_signal: int = signal.SIGKILL,
    env: dict[str, str] | None = None,
    **popen_kwargs: Any,
) -> subprocess.Popen[Any]:
    """Start `command` so that it dies with this process (see the module docstring).

    `started_for` is the state directory the child belongs to; `death_signal` is what it
    gets when this process dies (SIGTERM for a child that exits at once on it and has
    something worth saving, like mosquitto's persistence; SIGKILL otherwise).
    """
    child_env = {**(os.environ if env is None else env), STARTED_FOR: str(started_for)}
    wrapped = lifeline_command(list(command), death_signal)

    def start() -> subprocess.Popen[Any]:
        return subprocess.Popen(wrapped, env=child_env, **popen_kwargs)

    return _spawner.run(start)


__all__ = ["STARTED_FOR", "lifeline_command", "spawn"]
