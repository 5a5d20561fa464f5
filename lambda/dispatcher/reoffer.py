"""The schedule's watch over assigned tasks: a command that never reached its robot is
sent again, and a task that cannot be carried out any more is told, never dropped.

An assigned task's command may never have been published (the function stopped between
the assignment and the publish) or never reached its robot. The robot-freed rule cannot
notice: the robot stays idle, so its shadow changes no more. So once a minute the
dispatcher function reads the assigned tasks (`TaskTable.offers`), and for each whose
robot has not been seen with it for `REOFFER_AFTER_S` since it was assigned or last sent,
asks the fleet index for that robot's state (`FleetSearch.states`, about 40 robots a
search) and:

- the robot reports the task's command: it has it. Still at work: the task is marked
  acknowledged and never sent again. Finished (its rule event was lost): the task is
  closed as the robot-freed event would have, and the robot takes the next in line;
- the robot is offline or unknown to the index: the task is lost (`offline`);
- it was sent again `MAX_REOFFERS` times already: the task is lost (`unacknowledged`);
- otherwise its command is published again, with the same id, so a robot that had it
  after all runs it once.

A lost task ends (outcome `cancelled`) and is told (`tell`, the announcer function).
"""

from __future__ import annotations

import logging
from datetime import datetime
from typing import TYPE_CHECKING

import msgspec

from dispatcher.announcer_channel import lost_task
from dispatcher.errors import PublishError
from dispatcher.robot_updates import ACK_GRACE_S
from vahr.dispatch import FINAL_RESULTS, Dispatcher, Task, timestamp
from vahr.protocol.lost_tasks import LostTask  # noqa: TC001 - msgspec reads it at run time

if TYPE_CHECKING:
    from collections.abc import Callable

    from dispatcher.fleet_search import FleetSearch
    from dispatcher.task_table import Offer, TaskTable
    from vahr.protocol.lost_tasks import LostWhy

log = logging.getLogger("dispatcher")
# How long a command may take to show in its robot's shadow before it is sent again: the
# robot-freed rule's grace (a connected robot acknowledges well within a second).
REOFFER_AFTER_S = ACK_GRACE_S
# How often a command is sent again before its task is given up: with the schedule once a
# minute, a robot that never acknowledges loses its task after about four minutes.
MAX_REOFFERS = 3


class Watch(msgspec.Struct, frozen=True, kw_only=True):
    """What one look at the assigned tasks did: the tasks sent again, acknowledged, closed
    (finished while the rule event was lost), lost, and given to a robot so freed; and the
    queue as read."""

    offered_again: list[str] = []
    acknowledged: list[str] = []
    closed: list[str] = []
    lost: list[LostTask] = []
    given: list[Task] = []
    queued: list[Task] = []


def watch_assigned(
    dispatcher: Dispatcher,
    table: TaskTable,
    search: FleetSearch,
    *,
    now: datetime,
    tell: Callable[[LostTask], None],
) -> Watch:
    """Look once at every assigned task whose robot has not been seen with it."""
    assigned, queued = table.offers()
    due = [offer for offer in assigned if _due(offer, now)]
    if not due:
        return Watch(queued=queued)
    states = search.states(offer.task.thing for offer in due if offer.task.thing)
    offered: list[str] = []
    acknowledged: list[str] = []
    closed: list[str] = []
    lost: list[LostTask] = []
    given: list[Task] = []
    for offer in due:
        task = offer.task
        assert task.thing is not None
        state = states.get(task.thing)
        if state is not None and state.last_command_id == task.id:
            if state.last_result in FINAL_RESULTS:
                taken = dispatcher.observe(state)
                closed.append(task.id)
                if taken is not None:
                    given.append(taken)
            elif table.acknowledged(task):
                acknowledged.append(task.id)
            continue
        why: LostWhy | None = None
        if state is None or not state.connected:
            why = "offline"
        elif offer.offers >= MAX_REOFFERS:
            why = "unacknowledged"
        if why is None:
            # Counted first, on the version read: a task cancelled or finished meanwhile is
            # not sent again (its robot may have been told to stop).
            if not table.offered(task, at=timestamp(now)):
                continue
            try:
                dispatcher.publish(task.thing, Dispatcher.command_for(task))
            except PublishError as err:
                log.warning("task %s not sent again (next minute): %s", task.id, err)
                continue
            log.info("task %s sent again to %s (%d)", task.id, task.thing, offer.offers + 1)
            offered.append(task.id)
            continue
        ended = table.finish(task.id, outcome="cancelled")
        if ended is None:
            continue  # it changed meanwhile (finished, cancelled): nothing is lost
        news = lost_task(ended, why, now)
        log.warning("task %s (%s to %s) lost: %s %s", task.id, task.kind, task.zone,
                    task.thing, why)  # fmt: skip
        tell(news)
        lost.append(news)
    return Watch(
        offered_again=offered,
        acknowledged=acknowledged,
        closed=closed,
        lost=lost,
        given=given,
        queued=queued,
    )


def _due(offer: Offer, now: datetime) -> bool:
    """Not yet seen with its robot, and quiet for `REOFFER_AFTER_S` since last sent."""
    if offer.acknowledged:
        return False
    last = offer.offered_at or offer.task.assigned_at
    if last is None:
        return True
    sent = datetime.fromisoformat(last.replace("Z", "+00:00"))
    return (now - sent).total_seconds() >= REOFFER_AFTER_S
