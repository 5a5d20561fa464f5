"""What the skill says about batteries and about robots out of service (pure).

Battery answers read the robots' shadows (`reported.battery`), or for a large fleet what
the fleet index counts and finds; service answers read what the dispatcher did
(`ServiceChange`). Names are the fleet's, in the request's language.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import prompts
from skill.task_speech import and_list, spoken_number, task_name
from skill.vocabulary import capitalise, count_text

if TYPE_CHECKING:
    from collections.abc import Sequence

    from skill.iot_fleet_index import IndexedRobot
    from skill.robots import ShadowRead
    from skill.vocabulary import Vocabulary
    from vahr.dispatch import ServiceChange

# The robots a large fleet's answer names, the lowest charge first.
NAMED_MAX = 3


def one_battery(vocabulary: Vocabulary, read: ShadowRead) -> str:
    """ "Rover one has 12 percent battery." (and whether it charges, or is offline)."""
    robot = vocabulary.robot(read.thing)
    reported = read.shadow.reported if read.shadow is not None else None
    battery = reported.battery if reported is not None else None
    if reported is None or battery is None:
        return capitalise(prompts.BATTERY_UNKNOWN.format(robot=robot))
    if not reported.connected:
        wording = prompts.BATTERY_OFFLINE
    elif battery.charging:
        wording = prompts.BATTERY_CHARGING
    else:
        wording = prompts.BATTERY_LEVEL
    return capitalise(wording.format(robot=robot, percent=battery.percent))


def below(vocabulary: Vocabulary, percent: int, reads: Sequence[ShadowRead]) -> str:
    """The robots whose charge is under `percent`, lowest first."""
    low = []
    for read in reads:
        battery = read.shadow.reported.battery if read.shadow is not None else None
        if battery is not None and battery.percent < percent:
            low.append((battery.percent, read.thing, battery.charging))
    if not low:
        return prompts.BATTERY_BELOW_NONE.format(percent=percent)
    low.sort()
    entries = [_entry(vocabulary, thing, level, charging) for level, thing, charging in low]
    wording = prompts.BATTERY_BELOW[min(len(low), 2)]
    return capitalise(
        wording.format(count=spoken_number(len(low)), percent=percent, robots=and_list(entries))
    )


def below_in_index(
    vocabulary: Vocabulary, percent: int, count: int, found: Sequence[IndexedRobot]
) -> str:
    """A large fleet's robots under `percent`: `count` of them by the index, named from
    `found` (those the index returned: all of them, or a page), lowest first, at most
    `NAMED_MAX`."""
    low = sorted(
        (battery.percent, robot.thing, battery.charging)
        for robot in found
        if (battery := robot.reported.battery) is not None and battery.percent < percent
    )
    if not count or not low:
        return prompts.BATTERY_BELOW_NONE.format(percent=percent)
    entries = [_entry(vocabulary, thing, level, charging) for level, thing, charging in low]
    if count <= NAMED_MAX and len(low) == count:
        wording = prompts.BATTERY_BELOW[min(count, 2)]
    else:
        wording = prompts.BATTERY_BELOW_LOWEST if len(low) >= count else prompts.BATTERY_BELOW_AMONG
    return capitalise(
        wording.format(
            count=spoken_number(count), percent=percent, robots=and_list(entries[:NAMED_MAX])
        )
    )


def fleet_counts(total: int, percent: int, low: int, charging: int) -> str:
    """ "Of 1,000 robots, 12 are below 20 percent and 3 are charging. ...": a large fleet's
    batteries in two counts."""
    return prompts.BATTERY_FLEET_COUNTS.format(
        total=count_text(total),
        low=_counted(prompts.BATTERY_COUNTS["low"], low, percent=percent),
        charging=_counted(prompts.BATTERY_COUNTS["charging"], charging),
    )


def _counted(forms: tuple[str, ...], n: int, **values: object) -> str:
    """The form for none, one or many, with the number in it."""
    return forms[min(n, 2)].format(n=count_text(n), **values)


def every_battery(vocabulary: Vocabulary, reads: Sequence[ShadowRead]) -> str:
    """ "The batteries: rover one 80 percent, rover two 12 percent, charging ..."."""
    entries = []
    for read in reads:
        battery = read.shadow.reported.battery if read.shadow is not None else None
        if battery is None:
            continue
        entries.append(_entry(vocabulary, read.thing, battery.percent, battery.charging))
    if not entries:
        return capitalise(prompts.BATTERY_UNKNOWN.format(robot=vocabulary.robot("all")))
    return prompts.BATTERY_FLEET.format(robots=and_list(entries))


def _entry(vocabulary: Vocabulary, thing: str, percent: int, charging: bool) -> str:
    wording = prompts.BATTERY_ENTRY_CHARGING if charging else prompts.BATTERY_ENTRY
    return wording.format(robot=vocabulary.robot(thing), percent=percent)


def refused(vocabulary: Vocabulary, things: Sequence[str]) -> str:
    """ "Rover one is out of service, so I sent nothing."."""
    names = and_list([vocabulary.robot(thing) for thing in things])
    return capitalise(prompts.OUT_OF_SERVICE_REFUSED[min(len(things), 2)].format(robots=names))


def service_report(vocabulary: Vocabulary, changes: Sequence[ServiceChange]) -> str:
    """What taking robots out of service (or putting them back) did."""
    if not changes:
        return ""
    in_service = changes[0].in_service
    changed = [change.thing for change in changes if change.changed]
    unchanged = [change.thing for change in changes if not change.changed]
    sentences = []
    now = prompts.NOW_IN_SERVICE if in_service else prompts.NOW_OUT_OF_SERVICE
    already = prompts.ALREADY_IN_SERVICE if in_service else prompts.ALREADY_OUT_OF_SERVICE
    for things, wording in ((changed, now), (unchanged, already)):
        if things:
            names = and_list([vocabulary.robot(thing) for thing in things])
            sentences.append(capitalise(wording[min(len(things), 2)].format(robots=names)))
    for change in changes:
        for task in change.reassigned:
            if task.status == "assigned" and task.thing is not None:
                sentences.append(
                    capitalise(
                        prompts.SERVICE_REASSIGNED.format(
                            task=task_name(vocabulary, task), robot=vocabulary.robot(task.thing)
                        )
                    )
                )
            else:
                sentences.append(
                    capitalise(prompts.SERVICE_REQUEUED.format(task=task_name(vocabulary, task)))
                )
        if change.waiting and len(changes) == 1:
            waits = prompts.SERVICE_WAITING[min(len(change.waiting), 2)]
            sentences.append(capitalise(waits.format(count=spoken_number(len(change.waiting)))))
        for task in change.given:
            sentences.append(prompts.SERVICE_GIVEN.format(task=task_name(vocabulary, task)))
    return " ".join(sentences)
