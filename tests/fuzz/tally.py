"""How many generated inputs each boundary took, and what became of them.

Every fuzz test records each input as `accepted` or `rejected` (with the field its
rejection named); a crash, a hang or a wrong answer fails the test instead, so a finished
run's crash count is zero by construction. `bench/fuzz.py` reads the snapshot.
"""

from __future__ import annotations

import threading
from collections import Counter
from typing import Any

from hypothesis import settings


def budget(ci: int) -> int:
    """Inputs per test: `ci` under the ci profile, the profile's own count otherwise."""
    profile_examples: int = settings().max_examples
    return ci if profile_examples <= 100 else max(ci, profile_examples)


class InputTally:
    """Generated inputs per boundary: how many were accepted, and rejected by which field."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._counts: dict[str, Counter[str]] = {}
        self._fields: dict[str, Counter[str]] = {}

    def accepted(self, boundary: str) -> None:
        self._count(boundary, "accepted")

    def rejected(self, boundary: str, field: str) -> None:
        self._count(boundary, "rejected")
        with self._lock:
            self._fields.setdefault(boundary, Counter())[field] += 1

    def _count(self, boundary: str, outcome: str) -> None:
        with self._lock:
            self._counts.setdefault(boundary, Counter())[outcome] += 1

    def snapshot(self) -> dict[str, Any]:
        with self._lock:
            return {
                boundary: {
                    "tried": sum(counts.values()),
                    "accepted": counts["accepted"],
                    "rejected": counts["rejected"],
                    "fields": dict(self._fields.get(boundary, Counter()).most_common(8)),
                }
                for boundary, counts in sorted(self._counts.items())
            }


TALLY = InputTally()
