"""The audit trail's record of what the dispatcher does by itself: a queued task given to a
robot that came free (on `vahr up` and in the dispatcher function alike).

A person's order is recorded where they gave it (the skill, the tasks API), with who gave
it; a task given later, when a robot freed up, is the dispatcher's own act, recorded here
as channel `dispatcher` with the task's id as its command's.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.dispatch.tasks import SOURCE
from vahr.protocol.audit import AuditEntry, now

if TYPE_CHECKING:
    from vahr.dispatch.tasks import Task

# Who acts: the dispatcher itself.
DISPATCHER = "dispatcher"


def task_given(task: Task) -> AuditEntry:
    """The record of `task` given to its robot by the dispatcher itself (a robot low on
    charge sent to a charger is one too)."""
    charge = task.kind == "charge"
    return AuditEntry(
        time=now(),
        who=DISPATCHER,
        channel=SOURCE,
        intent=task.kind,
        slots={"zone": task.zone},
        robots=[task.thing] if task.thing else [],
        commands=[task.id],
        outcome="sent",
        reason="low on battery: sent to the nearest free charger"
        if charge
        else "a queued task given to a robot that came free",
    )
