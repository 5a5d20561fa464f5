"""No command moves a robot out of service: before a command that names robots is
published, the dispatcher (`TaskDesk.out_of_service`) says which robots are out of
service, and a command to one of them is not sent; the person hears why.

A stop always goes out (anyone may stop any robot at once). A dispatcher that cannot be
asked just now (unreachable, or one that keeps no service list) costs the check, not the
command: it is logged, and the command is sent.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill.errors import GatewayError
from skill.logs import log_event
from skill.task_desk import TaskRefused

if TYPE_CHECKING:
    from collections.abc import Iterable

    from skill.task_desk import TaskDesk


def out_of_service(desk: TaskDesk | None, things: Iterable[str]) -> list[str]:
    """Those of `things` out of service now, in their order; none when nobody can say."""
    wanted = list(things)
    if desk is None or not wanted:
        return []
    try:
        out = set(desk.out_of_service())
    except (GatewayError, TaskRefused) as err:
        log_event("out_of_service_unknown", reason=str(err))
        return []
    return [thing for thing in wanted if thing in out]
