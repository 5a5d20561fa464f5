"""No robot is sent into a closed zone: before a command that names a robot is published,
the dispatcher (`TaskDesk.closed_zones`) says which zones are closed, and a command into
one is not sent; the person hears that the zone is closed.

The robots refuse a closed zone themselves too (they read the retained closures), so a
dispatcher that cannot be asked just now costs the clear reply, not the rule: the command
is sent and the robot's refusal is spoken.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill.errors import GatewayError
from skill.logs import log_event
from skill.task_desk import TaskRefused

if TYPE_CHECKING:
    from collections.abc import Iterable

    from skill.task_desk import TaskDesk


def closed_zone(desk: TaskDesk | None, zones: Iterable[str | None]) -> str | None:
    """The first of `zones` that is closed now; None when none is, or nobody can say."""
    wanted = [zone for zone in zones if zone]
    if desk is None or not wanted:
        return None
    try:
        closed = set(desk.closed_zones())
    except (GatewayError, TaskRefused) as err:
        log_event("closed_zones_unknown", reason=str(err))
        return None
    return next((zone for zone in wanted if zone in closed), None)
