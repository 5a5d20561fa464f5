"""Whether `vahr up` can take a command yet: every robot online and the assistant able to
answer (its language model loaded, or learnt on a first start).

`Readiness` asks `awaiting` what is still missing, in words a person can act on, and holds
once nothing is: a robot that goes offline later is a fault the robots' status reports,
not a system still starting. `GET /vahr/health` answers from it, `POST /vahr/say` waits on
it, and `vahr up` prints its endpoints only once it holds.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

POLL_S = 0.05


class Readiness:
    def __init__(self, awaiting: Callable[[], list[str]]) -> None:
        self._awaiting = awaiting
        self._ready = threading.Event()

    @property
    def ready(self) -> bool:
        return not self.awaiting()

    def awaiting(self) -> list[str]:
        """What the system still waits for; empty once it can take a command."""
        if self._ready.is_set():
            return []
        missing = self._awaiting()
        if not missing:
            self._ready.set()
        return missing

    def wait(self, timeout_s: float) -> bool:
        """Block until ready (True) or `timeout_s` has passed (False)."""
        deadline = time.monotonic() + timeout_s
        while self.awaiting():
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            self._ready.wait(min(POLL_S, left))
        return True
