"""What is worth telling the person, decided the same way on AWS and on one machine.

`settings` holds the one typed, validated settings struct; `policy` turns robot events,
presence and (once a fleet queue exists) queued tasks into announcements, deduplicated per
robot and fault, rate-limited per person and ordered by priority, with the clock injected;
`speech` is what the assistant says for each kind. Pure: it imports only `vahr.protocol`,
so the cloud's announcer function carries it in its bundle.
"""

from __future__ import annotations

from vahr.announce.policy import (
    AnnouncePolicy,
    Cleared,
    Dispatched,
    Finished,
    LowBattery,
    Opened,
    PolicyState,
    Queued,
    Signal,
    TaskCancelled,
    signals_from_event,
    signals_from_presence,
)
from vahr.announce.settings import AnnounceSettings, settings_from

__all__ = [
    "AnnouncePolicy",
    "AnnounceSettings",
    "Cleared",
    "Dispatched",
    "Finished",
    "LowBattery",
    "Opened",
    "PolicyState",
    "Queued",
    "Signal",
    "TaskCancelled",
    "settings_from",
    "signals_from_event",
    "signals_from_presence",
]
