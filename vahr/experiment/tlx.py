"""NASA-TLX answers: six subscales on the 21-level scale, plus the paper's two questions.

The paper's questionnaire uses the NASA-TLX scale of 21 levels (ticks from "very low" to
"very high"); level 1 is 0 % and level 21 is 100 %, so percent = (level - 1) x 5. The two
extra questions, confidence and trust, use the same scale.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any

SUBSCALES = ("mental", "physical", "temporal", "performance", "effort", "frustration")
EXTRA_ITEMS = ("confidence", "trust")
ITEMS = SUBSCALES + EXTRA_ITEMS
LEVELS = 21

QUESTIONS = {
    "mental": "How mentally demanding was the task?",
    "physical": "How physically demanding was the task?",
    "temporal": "How hurried or rushed was the pace of the task?",
    "performance": "How successful were you in accomplishing what you were asked to do?",
    "effort": "How hard did you have to work to accomplish your level of performance?",
    "frustration": "How insecure, discouraged, irritated, stressed and annoyed were you?",
    "confidence": "How confident were you that the robots would do what you asked?",
    "trust": "How much did you trust the robots to complete the tasks without you?",
}

# Each item's name in the report's tables and figures.
ITEM_LABELS = {
    "mental": "Mental demand",
    "physical": "Physical demand",
    "temporal": "Temporal demand",
    "performance": "Performance",
    "effort": "Effort",
    "frustration": "Frustration",
    "confidence": "Confidence",
    "trust": "Trust",
}


def check_level(item: str, level: object) -> int:
    """Return `level` as an int if it is a whole level 1..21, else raise ValueError."""
    if isinstance(level, bool) or not isinstance(level, int | float | str):
        raise ValueError(f"{item}: {level!r} is not a level; levels are 1 to {LEVELS}")
    try:
        number = float(level)
    except ValueError:
        raise ValueError(f"{item}: {level!r} is not a level; levels are 1 to {LEVELS}") from None
    if not number.is_integer() or not 1 <= number <= LEVELS:
        raise ValueError(f"{item}: {level!r} is not a level; levels are 1 to {LEVELS}")
    return int(number)


def to_percent(level: int) -> float:
    """percent = (level - 1) x 5: level 1 -> 0 %, 11 -> 50 %, 21 -> 100 %."""
    return float((check_level("level", level) - 1) * 5)


@dataclass(frozen=True)
class TlxAnswers:
    """One participant's answers after one run, as levels 1..21."""

    mental: int
    physical: int
    temporal: int
    performance: int
    effort: int
    frustration: int
    confidence: int
    trust: int

    def __post_init__(self) -> None:
        for field in fields(self):
            check_level(field.name, getattr(self, field.name))

    @classmethod
    def from_mapping(cls, levels: dict[str, Any]) -> TlxAnswers:
        missing = [item for item in ITEMS if item not in levels]
        if missing:
            raise ValueError(f"missing answers for {', '.join(missing)}")
        unknown = sorted(set(levels) - set(ITEMS))
        if unknown:
            raise ValueError(f"{', '.join(unknown)}: not a questionnaire item")
        return cls(**{item: check_level(item, levels[item]) for item in ITEMS})

    def levels(self) -> dict[str, int]:
        return asdict(self)

    def percents(self) -> dict[str, float]:
        return {item: to_percent(level) for item, level in self.levels().items()}

    def raw_tlx(self) -> float:
        """The unweighted ("raw") TLX workload: the mean of the six subscales in percent."""
        percents = self.percents()
        return sum(percents[item] for item in SUBSCALES) / len(SUBSCALES)
