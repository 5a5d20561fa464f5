"""A fleet task the dispatcher could not see through, as it tells the announcer.

The dispatcher function invokes the announcer function with `{"lost_task": LostTask}`; the
local stack calls its announcer in-process with the same facts. `why` says what happened:

| why | what happened |
| --- | --- |
| `preempted` | its robot took the command, then was sent elsewhere by name |
| `offline` | its robot went offline before it acknowledged the task's command |
| `unacknowledged` | its robot stayed online but never acknowledged the command, sent again |
"""

from __future__ import annotations

from typing import Literal

import msgspec

from vahr.protocol.errors import from_validation_error
from vahr.protocol.messages import Timestamp  # noqa: TC001 - msgspec reads it at run time

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


def lost_task_from(value: object) -> LostTask:
    """Validate a lost task from JSON-like data; raises ProtocolError naming the field."""
    try:
        return msgspec.convert(value, LostTask, strict=False)
    except msgspec.ValidationError as err:
        raise from_validation_error(err) from err
