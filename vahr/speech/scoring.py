"""How an understanding is scored: each item's outcome counted, per group, with its rate.

The simulator's NLU (`vahr nlu --eval`: right, wrong, fallback, asks) and the robot's
hearing (`robot-agent hear --eval`: right, wrong, fallback) both count what became of each
labelled utterance or clip in an `OutcomeTally`; each names its own outcomes.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any


@dataclass
class OutcomeTally:
    """How many items of one group (an intent, a condition...) ended in each outcome."""

    # The outcomes reported, in order (an outcome never counted is reported as 0).
    outcomes: tuple[str, ...]
    counts: Counter[str] = field(default_factory=Counter)

    @property
    def total(self) -> int:
        return sum(self.counts.values())

    def rate(self, outcome: str) -> float:
        return self.counts[outcome] / self.total if self.total else 0.0

    def add(self, other: OutcomeTally) -> None:
        """Count `other`'s items here too."""
        self.counts.update(other.counts)

    def to_json(self) -> dict[str, Any]:
        rates = {f"{outcome}_rate": round(self.rate(outcome), 4) for outcome in self.outcomes}
        return {"n": self.total, **{o: self.counts[o] for o in self.outcomes}, **rates}
