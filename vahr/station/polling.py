"""A thread that calls `poll()` every `every_s` until stopped: how the station reads what
has no push feed (the dispatcher's queue, the audit trail) once for every page open."""

from __future__ import annotations

import threading


class Poller:
    """Calls `poll()` at once, then every `every_s`, on a daemon thread named `name`;
    `stop()` waits up to `join_s` for a poll under way. Subclasses define `poll`, which
    must not raise (a failed read is logged there and tried again next time)."""

    def __init__(self, name: str, *, every_s: float, join_s: float) -> None:
        self.every_s = every_s
        self._join_s = join_s
        self._stopped = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def poll(self) -> None:
        raise NotImplementedError

    def start(self) -> Poller:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stopped.set()
        if self._thread.is_alive():
            self._thread.join(self._join_s)

    def _run(self) -> None:
        while not self._stopped.is_set():
            self.poll()
            self._stopped.wait(self.every_s)
