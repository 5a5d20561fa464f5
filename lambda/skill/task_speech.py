"""What the skill says about fleet tasks (pure): a submission, the queue, a cancellation, a
zone closed or opened.

Sentences come from `skill.prompts`; robots are called by their first spoken name and
zones as `skill.vocabulary` says them. Places in line are ordinals ("first in line").
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import prompts
from skill.vocabulary import capitalise
from vahr.domain.text import number_in_words

if TYPE_CHECKING:
    from collections.abc import Sequence

    from skill.vocabulary import Vocabulary
    from vahr.dispatch import Order, Submission, Task, ZoneChange

# The queue is read out to this many tasks; the rest are counted.
QUEUE_READ_MAX = 5


def spoken_number(number: int) -> str:
    return number_in_words(number) or str(number)


def ordinal(place: int) -> str:
    if 1 <= place <= len(prompts.ORDINALS):
        return prompts.ORDINALS[place - 1]
    return prompts.ORDINAL_BEYOND.format(n=place)


def and_list(names: Sequence[str]) -> str:
    """ "heron", "heron and plover", "heron, plover and curlew"."""
    if len(names) <= 1:
        return "".join(names)
    return ", ".join(names[:-1]) + f" {prompts.AND} " + names[-1]


def task_name(vocabulary: Vocabulary, task: Task) -> str:
    """ "the delivery to the oven", "the trip to zone b"."""
    return prompts.TASK_NAMES[task.kind].format(zone=vocabulary.zone(task.zone))


def submission_report(vocabulary: Vocabulary, order: Order, submission: Submission) -> str:
    """Who took the order's tasks, and what waits and where in line."""
    zone = vocabulary.zone(order.zone)
    robots = [vocabulary.robot(task.thing) for task in submission.assigned if task.thing]
    sentences = []
    if len(robots) == 1:
        sentences.append(prompts.DISPATCHED[order.kind].format(robot=robots[0], zone=zone))
    elif robots:
        sentences.append(
            prompts.DISPATCHED_MANY[order.kind].format(robots=and_list(robots), zone=zone)
        )
    queued = submission.queued
    if queued:
        place = ordinal(submission.positions[0]) if submission.positions else ordinal(1)
        if order.group is not None and order.count is None:
            # A group's task waits for its own member.
            members = [vocabulary.robot(task.robots[0]) for task in queued if task.robots]
            verb = "is" if len(members) == 1 else "are"
            sentences.append(prompts.MEMBERS_BUSY.format(robots=and_list(members), verb=verb))
        elif robots:
            wording = prompts.QUEUED_REST[min(len(queued), 2)]
            sentences.append(wording.format(count=spoken_number(len(queued)), place=place))
        elif len(queued) == 1:
            sentences.append(
                prompts.ALL_BUSY.format(task=task_name(vocabulary, queued[0]), place=place)
            )
        else:
            tasks = prompts.TASK_NAMES_PLURAL[order.kind].format(zone=zone)
            sentences.append(
                prompts.ALL_BUSY_MANY.format(
                    count=spoken_number(len(queued)), tasks=tasks, place=place
                )
            )
    return " ".join(capitalise(sentence) for sentence in sentences)


def queue_report(
    vocabulary: Vocabulary, tasks: Sequence[Task], *, closed: Sequence[str] = ()
) -> str:
    """The queue, next first: "2 queued: first, the delivery to the oven; second, ...". A
    task into a `closed` zone is said to wait until the zone opens."""
    queued = [task for task in tasks if task.status == "queued"]
    if not queued:
        return prompts.QUEUE_EMPTY
    entries = []
    for place, task in enumerate(queued[:QUEUE_READ_MAX], start=1):
        name = task_name(vocabulary, task)
        shut = next((zone for zone in (task.pickup, task.zone) if zone in closed), None)
        if shut is None:
            entries.append(prompts.QUEUE_ENTRY.format(place=ordinal(place), task=name))
        else:
            entries.append(
                prompts.QUEUE_ENTRY_WAITING.format(
                    place=ordinal(place), task=name, zone=vocabulary.zone(shut)
                )
            )
    if len(queued) > QUEUE_READ_MAX:
        entries.append(prompts.QUEUE_MORE.format(count=len(queued) - QUEUE_READ_MAX))
    wording = prompts.QUEUE_LISTED[min(len(queued), 2)]
    listed = wording.format(count=spoken_number(len(queued)), tasks="; ".join(entries))
    return capitalise(listed)


def tasks_to_cancel(tasks: Sequence[Task], zone: str) -> list[tuple[Task, int]]:
    """What "cancel the delivery to {zone}" cancels: every open task to that zone, each
    with its place in line (0 for one a robot holds), robots' first, then the queue's.
    One sentence cannot tell two tasks to one zone apart, so all of them go, and the
    answer says how many and which robots it stopped (docs/dispatch.md)."""
    queued = [task for task in tasks if task.status == "queued"]
    held = [(task, 0) for task in tasks if task.status == "assigned" and task.zone == zone]
    waiting = [(task, place) for place, task in enumerate(queued, start=1) if task.zone == zone]
    return held + waiting


def cancel_report(vocabulary: Vocabulary, cancelled: Sequence[tuple[Task, int]]) -> str:
    """ "I cancelled the delivery to zone b and stopped heron.", or for several: "I
    cancelled the two tasks to zone b and stopped heron and plover."."""
    if len(cancelled) == 1:
        task, place = cancelled[0]
        name = task_name(vocabulary, task)
        if place > 0 or task.thing is None:
            sentence = prompts.CANCELLED_QUEUED.format(task=name, place=ordinal(max(place, 1)))
        else:
            sentence = prompts.CANCELLED_HELD.format(task=name, robot=vocabulary.robot(task.thing))
        return capitalise(sentence)
    zone = vocabulary.zone(cancelled[0][0].zone)
    stopped = [
        vocabulary.robot(task.thing) for task, place in cancelled if place == 0 and task.thing
    ]
    count = spoken_number(len(cancelled))
    if stopped:
        sentence = prompts.CANCELLED_MANY_STOPPED.format(
            count=count, zone=zone, robots=and_list(stopped)
        )
    else:
        sentence = prompts.CANCELLED_MANY.format(count=count, zone=zone)
    return capitalise(sentence)


def zone_change_report(vocabulary: Vocabulary, change: ZoneChange) -> str:
    """ "Zone B is closed. No robot will be sent there until it opens. One queued task to
    it waits until it opens." / "Zone B is open again. Heron took the task that waited."."""
    zone = vocabulary.zone(change.zone)
    if change.closed:
        first = prompts.ZONE_NOW_CLOSED if change.changed else prompts.ZONE_ALREADY_CLOSED
    else:
        first = prompts.ZONE_NOW_OPEN if change.changed else prompts.ZONE_ALREADY_OPEN
    sentences = [first.format(zone=zone)]
    if change.given:
        robots = [vocabulary.robot(task.thing) for task in change.given if task.thing]
        wording = prompts.ZONE_GIVEN[min(len(change.given), 2)]
        sentences.append(wording.format(robots=and_list(robots)))
    if change.closed and change.waiting:
        wording = prompts.ZONE_WAITING[min(len(change.waiting), 2)]
        sentences.append(wording.format(count=spoken_number(len(change.waiting))))
    return " ".join(capitalise(sentence) for sentence in sentences)
