"""How an understanding is scored: a labelled set read, and each item's outcome counted,
per group, with its rate.

The simulator's NLU (`vahr nlu --eval`: right, wrong, fallback, asks) and the robot's
hearing (`robot-agent hear --eval`: right, wrong, fallback) both read their labelled set
with `read_labelled_set` and count what became of each utterance or clip in an
`OutcomeTally`; each names its own outcomes.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TypeVar

import msgspec

from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path

LabelledSet = TypeVar("LabelledSet", bound=msgspec.Struct)


def read_labelled_set(path: Path, kind: type[LabelledSet]) -> LabelledSet:
    """The YAML file at `path` as a `kind`, or one `VahrError` line saying what is wrong."""
    try:
        source = path.read_bytes()
    except OSError as err:
        raise VahrError(f"cannot read {path}: {err.strerror}") from err
    try:
        return msgspec.yaml.decode(source, type=kind)
    except msgspec.ValidationError as err:
        raise VahrError(f"{path}: {err}") from err
    except msgspec.DecodeError as err:
        raise VahrError(f"{path} is not valid YAML: {err}") from err


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
