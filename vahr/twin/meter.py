"""Count what AWS IoT Core would bill for: messages and Device Shadow operations.

AWS meters messages in 5 KB increments and shadow operations (get, update, delete, list)
in 1 KB increments. The local data plane and shadow service record every operation here
so a benchmark can state the billable operations a voice command costs.
"""

from __future__ import annotations

import math
import threading
from collections import Counter

MESSAGE_UNIT_BYTES = 5 * 1024
SHADOW_UNIT_BYTES = 1024


class Meter:
    """Thread-safe counters: `operations` (by kind) and billing `units` (by kind)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._operations: Counter[str] = Counter()
        self._units: Counter[str] = Counter()

    def message(self, kind: str, size: int) -> None:
        """A message published (e.g. `http.publish`, `mqtt.shadow.update`)."""
        self._record(kind, max(1, math.ceil(size / MESSAGE_UNIT_BYTES)))

    def shadow(self, kind: str, size: int) -> None:
        """A shadow operation (e.g. `http.shadow.get`), billed per started kilobyte."""
        self._record(kind, max(1, math.ceil(size / SHADOW_UNIT_BYTES)))

    def _record(self, kind: str, units: int) -> None:
        with self._lock:
            self._operations[kind] += 1
            self._units[kind] += units

    def snapshot(self) -> dict[str, dict[str, int]]:
        with self._lock:
            return {"operations": dict(self._operations), "units": dict(self._units)}

    def reset(self) -> None:
        with self._lock:
            self._operations.clear()
            self._units.clear()
