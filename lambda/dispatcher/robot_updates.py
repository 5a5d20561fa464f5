"""A robot became free: close what it finished, then give it the first queued task.

The core's `Dispatcher.observe` decides, with one thing it cannot know inside a Lambda
function: whether the robot acknowledged its task before reporting another command. The
local dispatcher sees every shadow update in one long-lived process and remembers that;
the function sees only the updates the rule selects (the robot became idle or stopped),
each perhaps in a fresh process. So here a robot that is free while the table says it
holds a task, and reports a different command as its last, lost that task to a command
given by name (or never got it) once `ACK_GRACE_S` has passed since the assignment;
before that, its task's command may still be on its way and nothing is changed. The task
so given up is told (`tell`: the announcer function), as the local stack tells it.
"""

from __future__ import annotations

import logging
from datetime import datetime
from typing import TYPE_CHECKING

from dispatcher.announcer_channel import lost_task

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.dispatch import Dispatcher, RobotState, Task
    from vahr.protocol.lost_tasks import LostTask

log = logging.getLogger("dispatcher")
# Longer than a command takes to reach a connected robot and be acknowledged in its shadow
# (well under a second on AWS IoT; the skill itself waits 2.5 s) with room for the index
# and the rule's own delivery.
ACK_GRACE_S = 30.0


def held_by(dispatcher: Dispatcher, thing: str) -> Task | None:
    for task in dispatcher.store.active():
        if task.thing == thing:
            return task
    return None


def robot_freed(
    dispatcher: Dispatcher,
    state: RobotState,
    *,
    now: datetime,
    tell: Callable[[LostTask], None] | None = None,
) -> Task | None:
    """Record what the robot's update ends and give it its next task; the task it took."""
    held = held_by(dispatcher, state.thing)
    if held is not None and state.last_command_id != held.id and held.assigned_at:
        assigned = datetime.fromisoformat(held.assigned_at.replace("Z", "+00:00"))
        if (now - assigned).total_seconds() >= ACK_GRACE_S:
            log.info("task %s: %s is free on another command; preempted", held.id, state.thing)
            given_up = dispatcher.store.finish(held.id, outcome="preempted")
            if given_up is not None and tell is not None:
                tell(lost_task(given_up, "preempted", now))
    return dispatcher.observe(state)
