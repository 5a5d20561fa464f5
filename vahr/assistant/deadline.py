"""How long the person who spoke waits for the answer, so that a turn they gave up on does
nothing afterwards.

A caller of `POST /vahr/say` says how long it waits (`timeout_s`); the turn must start by
`start_by` (early enough for the skill to finish inside Alexa's limit, `TURN_BUDGET_S`) and
may publish commands only until `answer_by`. A turn that cannot start in time is refused
(`TurnNotStarted`) before anything is understood or sent, and a command the skill would
publish after `answer_by` is refused at the data plane: either way the robots never act on
a request whose asker was told it failed.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from vahr.errors import VahrError

# What a started turn may take: Alexa's own limit, which the skill is built to answer in.
TURN_BUDGET_S = 8.0
# Time for the answer to travel back to the asker after the turn ends.
REPLY_MARGIN_S = 1.0


class TurnNotStarted(VahrError):
    """The turn could not start while its asker was still waiting; nothing was done."""


@dataclass(frozen=True)
class TurnDeadline:
    """When a turn must start, and until when it may send commands (monotonic seconds)."""

    start_by: float
    answer_by: float

    @classmethod
    def within(cls, timeout_s: float, *, now: float | None = None) -> TurnDeadline:
        """The deadline of a turn whose asker waits `timeout_s` from `now`."""
        at = time.monotonic() if now is None else now
        answer_by = at + timeout_s - REPLY_MARGIN_S
        return cls(start_by=answer_by - TURN_BUDGET_S, answer_by=answer_by)

    def start_left(self, now: float | None = None) -> float:
        """Seconds left to start the turn (negative once too late)."""
        return self.start_by - (time.monotonic() if now is None else now)

    def may_publish(self, now: float | None = None) -> bool:
        return (time.monotonic() if now is None else now) <= self.answer_by
