"""What the dispatcher tells the announcer: a fleet task it could not see through, and a
robot it sent to charge by itself.

The dispatcher function invokes the announcer function with `{"lost_task": LostTask}` or
`{"gone_to_charge": GoneToCharge}`; the local stack calls its announcer in-process with the
same facts. A lost task's `why` says what happened:

| why | what happened |
| --- | --- |
| `preempted` | its robot took the command, then was sent elsewhere by name |
| `offline` | its robot went offline before it acknowledged the task's command |
| `unacknowledged` | its robot stayed online but never acknowledged the command, sent again |
"""

from __future__ import annotations

from typing import Literal, TypeVar

import msgspec

from vahr.protocol.errors import from_validation_error
from vahr.protocol.messages import Timestamp  # noqa: TC001 - msgspec reads it at run time

_T = TypeVar("_T")

LostWhy = Literal["preempted", "offline", "unacknowledged"]
LOST_WHYS: tuple[LostWhy, ...] = ("preempted", "offline", "unacknowledged")
# The key of the announcer's invocation payload that holds a `LostTask`.
LOST_TASK_KEY = "lost_task"


class LostTask(msgspec.Struct, frozen=True, kw_only=True):
    """Task `task` (a `deliver` or `navigate` to `zone`) that `thing` held has ended
    without being done, at `at`, for the reason `why`."""

    task: str
    thing: str
    kind: str
    zone: str
    at: Timestamp
    why: LostWhy


# The key of the announcer's invocation payload that holds a `GoneToCharge`.
GONE_TO_CHARGE_KEY = "gone_to_charge"


class GoneToCharge(msgspec.Struct, frozen=True, kw_only=True):
    """Robot `thing`, low on charge, was sent by the dispatcher to the charger `zone` at
    `at`: it leaves the pool until it is charged."""

    thing: str
    zone: str
    at: Timestamp


# What the dispatcher tells the announcer.
Tidings = LostTask | GoneToCharge


def lost_task_from(value: object) -> LostTask:
    """Validate a lost task from JSON-like data; raises ProtocolError naming the field."""
    return _converted(value, LostTask)


def gone_to_charge_from(value: object) -> GoneToCharge:
    """Validate a robot gone to charge from JSON-like data; raises ProtocolError naming
    the field."""
    return _converted(value, GoneToCharge)


def _converted(value: object, kind: type[_T]) -> _T:
    try:
        return msgspec.convert(value, kind, strict=False)
    except msgspec.ValidationError as err:
        raise from_validation_error(err) from err
