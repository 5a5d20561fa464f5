"""What to say about commands and robot state (pure functions, no AWS).

The sentences themselves live in `skill.prompts`; this module only picks and fills them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import prompts
from skill.vocabulary import capitalise

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from skill.acknowledgment import RobotAnswer
    from skill.commands import Dispatch
    from skill.robots import ShadowRead
    from skill.vocabulary import Vocabulary
    from vahr.protocol import Reported

DELIVERY_TASKS = ("deliver", "weather_delivery", "sequential_delivery")


def _reason(answer: RobotAnswer) -> str:
    return (answer.reason or prompts.NO_REASON).rstrip(". ")


def _zone_of(item: Dispatch) -> str | None:
    zone = getattr(item.command.params, "zone", None)
    return zone if isinstance(zone, str) else None


def command_report(
    vocabulary: Vocabulary, item: Dispatch, answers: Mapping[str, RobotAnswer]
) -> str:
    """What happened to one dispatch: acknowledged, rejected, or not confirmed."""
    mine = [answers[thing] for thing in item.recipients]
    zone = _zone_of(item)
    zone_name = vocabulary.zone(zone) if zone else ""
    action = item.command.action
    if not item.to_fleet or len(mine) == 1:
        answer = mine[0]
        robot = vocabulary.robot(answer.thing)
        if answer.confirmed:
            after = getattr(item.command.params, "after", None)
            key = f"{action}_after" if isinstance(after, str) else action
            sentence = prompts.ACKNOWLEDGED[key].format(
                robot=robot, zone=zone_name, after=vocabulary.robot(after) if after else ""
            )
            return capitalise(sentence)
        return capitalise(_problem(robot, answer, _SINGLE_PROBLEMS))
    confirmed = [answer for answer in mine if answer.confirmed]
    if len(confirmed) == len(mine):
        robots = (
            prompts.BOTH_ROBOTS if len(mine) == 2 else prompts.ALL_ROBOTS.format(count=len(mine))
        )
        return prompts.FLEET_ACKNOWLEDGED[action].format(robots=robots, zone=zone_name)
    problems = "; ".join(
        _problem(vocabulary.robot(answer.thing), answer, _FLEET_PROBLEMS)
        for answer in mine
        if not answer.confirmed
    )
    template = prompts.FLEET_PARTIAL if confirmed else prompts.FLEET_NONE
    return template.format(confirmed=len(confirmed), count=len(mine), problems=problems)


def sequential_report(
    vocabulary: Vocabulary, items: Sequence[Dispatch], answers: Mapping[str, RobotAnswer]
) -> str:
    """Task III: both robots confirmed, or what went wrong with each."""
    first, second = items
    if all(answers[item.target].confirmed for item in items):
        return capitalise(
            prompts.SEQUENTIAL_ACKNOWLEDGED.format(
                first=vocabulary.robot(first.target),
                first_zone=vocabulary.zone(_zone_of(first) or ""),
                second=vocabulary.robot(second.target),
                second_zone=vocabulary.zone(_zone_of(second) or ""),
            )
        )
    parts = [command_report(vocabulary, item, answers) for item in items]
    return prompts.SEQUENTIAL_PARTIAL + " ".join(parts)


# A single robot's problem is a sentence of its own; in a fleet answer it is one clause of
# a list, so the same outcomes are worded shorter.
_SINGLE_PROBLEMS = {
    "rejected": prompts.REJECTED,
    "failed": prompts.FAILED,
    "cancelled": prompts.CANCELLED,
    "offline": prompts.OFFLINE,
    "silent": prompts.NOT_CONFIRMED,
}
_FLEET_PROBLEMS = {
    "rejected": prompts.PROBLEM_REJECTED,
    "failed": prompts.PROBLEM_FAILED,
    "cancelled": prompts.PROBLEM_CANCELLED,
    "offline": prompts.PROBLEM_OFFLINE,
    "silent": prompts.PROBLEM_SILENT,
}


def _problem(robot: str, answer: RobotAnswer, wording: Mapping[str, str]) -> str:
    """Why `answer` is not a confirmation, in `wording`'s sentence for that case."""
    case: str = answer.outcome
    if case not in ("rejected", "failed", "cancelled"):
        case = "offline" if answer.offline else "silent"
    return wording[case].format(robot=robot, reason=_reason(answer))


def status_report(vocabulary: Vocabulary, reads: Sequence[ShadowRead]) -> str:
    """One sentence per robot: 'Placebot one is carrying a package to zone B. ...'"""
    return " ".join(robot_status(vocabulary, read) for read in reads)


def robot_status(vocabulary: Vocabulary, read: ShadowRead) -> str:
    robot = vocabulary.robot(read.thing)
    if read.error is not None:
        return capitalise(prompts.STATUS_UNREADABLE.format(robot=robot))
    if read.shadow is None:
        return capitalise(prompts.STATUS_NEVER_REPORTED.format(robot=robot))
    return capitalise(_reported_status(vocabulary, robot, read.shadow.reported))


def _reported_status(vocabulary: Vocabulary, robot: str, state: Reported) -> str:
    here = vocabulary.zone(state.zone) if state.zone else None
    there = vocabulary.zone(state.destination) if state.destination else None
    if not state.connected:
        if here:
            return prompts.STATUS_OFFLINE_LAST_SEEN.format(robot=robot, zone=here)
        return prompts.STATUS_OFFLINE.format(robot=robot)
    status = state.status
    if status == "idle":
        return (prompts.STATUS_IDLE_IN if here else prompts.STATUS_IDLE).format(
            robot=robot, zone=here
        )
    if status == "navigating":
        return _moving(robot, state, there)
    if status == "loading":
        return prompts.STATUS_LOADING.format(robot=robot, zone=here or vocabulary.zone("LOADING"))
    if status == "unloading":
        return prompts.STATUS_UNLOADING.format(robot=robot, zone=here or there or "its zone")
    if status == "waiting":
        if state.task == "weather_delivery":
            return prompts.STATUS_WAITING_WEATHER.format(robot=robot)
        if state.task == "sequential_delivery" and there:
            return prompts.STATUS_WAITING_TURN.format(robot=robot, zone=there)
        return prompts.STATUS_WAITING.format(robot=robot)
    if status == "stopped":
        return (prompts.STATUS_STOPPED_IN if here else prompts.STATUS_STOPPED).format(
            robot=robot, zone=here
        )
    if status == "stuck":
        return (prompts.STATUS_STUCK_TO if there else prompts.STATUS_STUCK).format(
            robot=robot, zone=there
        )
    last = state.last_command
    if last is not None and last.reason:
        return prompts.STATUS_ERROR_REASON.format(robot=robot, reason=last.reason.rstrip(". "))
    return prompts.STATUS_ERROR.format(robot=robot)


def _moving(robot: str, state: Reported, there: str | None) -> str:
    if state.cargo and there:
        return prompts.STATUS_CARRYING.format(robot=robot, zone=there)
    if state.task in DELIVERY_TASKS and not state.cargo:
        if state.destination == "LOADING" or there is None:
            return prompts.STATUS_FETCHING.format(robot=robot)
        return prompts.STATUS_FETCHING_FOR.format(robot=robot, zone=there)
    if there:
        return prompts.STATUS_MOVING_TO.format(robot=robot, zone=there)
    return prompts.STATUS_MOVING.format(robot=robot)
