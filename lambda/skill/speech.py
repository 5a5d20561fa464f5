"""What to say about commands and robot state (pure functions, no AWS).

The sentences themselves live in `skill.prompts`; this module only picks and fills them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import prompts
from skill.vocabulary import capitalise, count_text

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from skill.acknowledgment import RobotAnswer
    from skill.commands import Publication
    from skill.fleet_status import FleetState
    from skill.iot_fleet_index import IndexedRobot
    from skill.robots import ShadowRead
    from skill.vocabulary import Vocabulary
    from vahr.protocol import Reported

DELIVERY_TASKS = ("deliver", "weather_delivery", "sequential_delivery")


def _reason(vocabulary: Vocabulary, answer: RobotAnswer, zone: str | None) -> str:
    """Why a robot did not confirm, with the command's zone (`zone`) said by its name."""
    if not answer.reason:
        return prompts.NO_REASON
    return vocabulary.reason(answer.reason, zone).rstrip(". ")


def _zone_of(item: Publication) -> str | None:
    zone = getattr(item.command.params, "zone", None)
    return zone if isinstance(zone, str) else None


def command_report(
    vocabulary: Vocabulary, item: Publication, answers: Mapping[str, RobotAnswer]
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
        return capitalise(_problem(vocabulary, robot, answer, _SINGLE_PROBLEMS, zone))
    confirmed = [answer for answer in mine if answer.confirmed]
    if len(confirmed) == len(mine):
        robots = (
            prompts.BOTH_ROBOTS
            if len(mine) == 2
            else prompts.ALL_ROBOTS.format(count=count_text(len(mine)))
        )
        return prompts.FLEET_ACKNOWLEDGED[action].format(robots=robots, zone=zone_name)
    unconfirmed = [answer for answer in mine if not answer.confirmed]
    # A fleet of a thousand cannot hear every missing robot: the first few by name.
    named = [
        _problem(vocabulary, vocabulary.robot(answer.thing), answer, _FLEET_PROBLEMS, zone)
        for answer in unconfirmed[:FLEET_PROBLEMS_NAMED]
    ]
    if len(unconfirmed) > FLEET_PROBLEMS_NAMED:
        named.append(prompts.FLEET_PROBLEMS_MORE.format(n=len(unconfirmed) - FLEET_PROBLEMS_NAMED))
    template = prompts.FLEET_PARTIAL if confirmed else prompts.FLEET_NONE
    return template.format(
        confirmed=count_text(len(confirmed)), count=count_text(len(mine)), problems="; ".join(named)
    )


def sequential_report(
    vocabulary: Vocabulary, items: Sequence[Publication], answers: Mapping[str, RobotAnswer]
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
# a list, so the same outcomes are worded shorter. By the message's name: each is read when
# spoken, in the request's language.
_SINGLE_PROBLEMS = {
    "rejected": "REJECTED",
    "failed": "FAILED",
    "cancelled": "CANCELLED",
    "offline": "OFFLINE",
    "silent": "NOT_CONFIRMED",
}
_FLEET_PROBLEMS = {
    "rejected": "PROBLEM_REJECTED",
    "failed": "PROBLEM_FAILED",
    "cancelled": "PROBLEM_CANCELLED",
    "offline": "PROBLEM_OFFLINE",
    "silent": "PROBLEM_SILENT",
}


def _problem(
    vocabulary: Vocabulary,
    robot: str,
    answer: RobotAnswer,
    wording: Mapping[str, str],
    zone: str | None,
) -> str:
    """Why `answer` is not a confirmation, in `wording`'s sentence for that case."""
    case: str = answer.outcome
    if case not in ("rejected", "failed", "cancelled"):
        case = "offline" if answer.offline else "silent"
    sentence: str = getattr(prompts, wording[case])
    return sentence.format(robot=robot, reason=_reason(vocabulary, answer, zone))


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


def _nearest_zone(vocabulary: Vocabulary, state: Reported) -> str | None:
    """The zone nearest the robot's reported pose, by its spoken name (None without one)."""
    zones = vocabulary.fleet.zones
    if state.pose is None or not zones:
        return None
    pose = state.pose
    nearest = min(zones, key=lambda z: (z.pose.x - pose.x) ** 2 + (z.pose.y - pose.y) ** 2)
    return vocabulary.zone(nearest.id)


def _reported_status(vocabulary: Vocabulary, robot: str, state: Reported) -> str:
    here = vocabulary.zone(state.zone) if state.zone else None
    there = vocabulary.zone(state.destination) if state.destination else None
    # Between zones, the nearest place says where the robot is.
    near = None if here else _nearest_zone(vocabulary, state)
    if not state.connected:
        if here:
            return prompts.STATUS_OFFLINE_LAST_SEEN.format(robot=robot, zone=here)
        if near:
            return prompts.STATUS_OFFLINE_LAST_SEEN_NEAR.format(robot=robot, zone=near)
        return prompts.STATUS_OFFLINE.format(robot=robot)
    status = state.status
    if status == "idle":
        if here:
            return prompts.STATUS_IDLE_IN.format(robot=robot, zone=here)
        if near:
            return prompts.STATUS_IDLE_NEAR.format(robot=robot, zone=near)
        return prompts.STATUS_IDLE.format(robot=robot)
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
        if here:
            return prompts.STATUS_STOPPED_IN.format(robot=robot, zone=here)
        if near:
            return prompts.STATUS_STOPPED_NEAR.format(robot=robot, zone=near)
        return prompts.STATUS_STOPPED.format(robot=robot)
    if status == "stuck":
        # A stuck robot's task has ended; the zone it was for is its last command's.
        last = state.last_command
        goal = there or (vocabulary.zone(last.zone) if last is not None and last.zone else None)
        if goal:
            return prompts.STATUS_STUCK_TO.format(robot=robot, zone=goal)
        if near:
            return prompts.STATUS_STUCK_NEAR.format(robot=robot, zone=near)
        return prompts.STATUS_STUCK.format(robot=robot)
    last = state.last_command
    if last is not None and last.reason:
        reason = vocabulary.reason(last.reason, last.zone).rstrip(". ")
        return prompts.STATUS_ERROR_REASON.format(robot=robot, reason=reason)
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


# -- status of a large fleet ------------------------------------------------------------

# A spoken answer about the fleet stays within this many words (about 20 s of speech).
MAX_WORDS = 60
# Statuses that are not trouble, in the order a tie is spoken.
_CALM = ("idle", "navigating", "loading", "unloading", "waiting", "stopped")
# Troubles go last in the opening, so that the first one named can follow it after a colon.
_TROUBLE_CLAUSES = ("error", "stuck")
# Unconfirmed robots a fleet command's reply names before "and N more".
FLEET_PROBLEMS_NAMED = 3


def words(text: str) -> int:
    return len(text.split())


def _counted(template: tuple[str, str], n: int) -> str:
    return template[0 if n == 1 else 1].format(n=count_text(n))


def _joined(parts: Sequence[str]) -> str:
    if len(parts) <= 1:
        return "".join(parts)
    return ", ".join(parts[:-1]) + f" {prompts.AND} " + parts[-1]


def _place(vocabulary: Vocabulary, robot: IndexedRobot) -> str:
    """'rover 17 in zone C', 'rover 230 near zone A' (by its pose), or just 'rover 5'."""
    name = vocabulary.robot(robot.thing)
    state = robot.reported
    if state.zone:
        return prompts.SUMMARY_IN.format(robot=name, zone=vocabulary.zone(state.zone))
    zones = vocabulary.fleet.zones
    if state.pose is not None and zones:
        pose = state.pose
        nearest = min(zones, key=lambda z: (z.pose.x - pose.x) ** 2 + (z.pose.y - pose.y) ** 2)
        return prompts.SUMMARY_NEAR.format(robot=name, zone=vocabulary.zone(nearest.id))
    return name


def _names(
    vocabulary: Vocabulary, robots: Sequence[IndexedRobot], count: int, budget: int
) -> str | None:
    """As many of `robots` (of `count` in all) as fit in `budget` words, then 'N more';
    None when not even one fits."""
    places = [_place(vocabulary, robot) for robot in robots]
    for shown in range(len(places), 0, -1):
        rest = count - shown
        parts = places[:shown] + ([prompts.SUMMARY_MORE.format(n=count_text(rest))] if rest else [])
        text = _joined(parts)
        if words(text) <= budget:
            return text
    return None


def _count_wording(status: str) -> tuple[str, str]:
    # A status newer than this skill is still counted, in its own word.
    return prompts.SUMMARY_COUNTS.get(status, ("{n} is " + status, "{n} are " + status))


def fleet_summary(vocabulary: Vocabulary, state: FleetState) -> str:
    """'Of 1,000 robots, 990 are idle, 8 are driving and 2 are stuck: rover 17 in zone C and
    rover 230 near zone A.' Counts by status, then the robots in trouble, stuck first, in
    at most `MAX_WORDS` words (the offline count is said even when no name fits)."""
    calm = sorted(
        (status for status, n in state.counts.items() if n and status not in _TROUBLE_CLAUSES),
        key=lambda status: (
            -state.counts[status],
            _CALM.index(status) if status in _CALM else len(_CALM),
        ),
    )
    clauses = [_counted(_count_wording(status), state.counts[status]) for status in calm]
    if state.unreported:
        clauses.append(_counted(prompts.SUMMARY_COUNTS["unreported"], state.unreported))
    troubles = [status for status in _TROUBLE_CLAUSES if state.counts.get(status)]
    clauses += [_counted(prompts.SUMMARY_COUNTS[s], state.counts[s]) for s in troubles]
    text = prompts.SUMMARY_OPENING.format(total=count_text(state.total), counts=_joined(clauses))
    # The trouble named right after the counts (after a colon), and the sentences after it.
    attached = troubles[-1] if troubles else None
    leads: dict[str, str] = {}
    for kind in ("stuck", "error", "offline"):
        if kind == attached or not state.trouble_count(kind):
            continue
        if kind == "offline":
            leads[kind] = _capitalised(_counted(prompts.SUMMARY_COUNTS["offline"], state.offline))
        elif state.troubled.get(kind):
            leads[kind] = prompts.SUMMARY_LABELS[kind]
    order = [kind for kind in ("stuck", "error", "offline") if kind == attached or kind in leads]
    for position, kind in enumerate(order):
        later = sum(words(leads[k]) for k in order[position + 1 :] if k == "offline")
        lead = "" if kind == attached else leads[kind]
        budget = MAX_WORDS - words(text) - words(lead) - later
        names = _names(vocabulary, state.troubled.get(kind, []), state.trouble_count(kind), budget)
        if kind == attached:
            text += f": {names}" if names else ""
        elif names:
            text += f". {lead}: {names}"
        elif kind == "offline":
            text += f". {lead}"
    return text + "."


def _capitalised(text: str) -> str:
    return text[:1].upper() + text[1:]


def problem_report(vocabulary: Vocabulary, state: FleetState) -> str:
    """'2 robots are stuck: rover 17 in zone C and rover 230 near zone A. 1 robot has
    failed: rover 5 in zone B.' Stuck, failed, then offline, in at most `MAX_WORDS` words;
    every count is said, names as far as the bound allows."""
    leads = {
        kind: _counted(prompts.PROBLEMS[kind], state.trouble_count(kind))
        for kind in ("stuck", "error", "offline")
        if state.trouble_count(kind)
    }
    if not leads:
        return prompts.PROBLEMS_NONE
    sentences: list[str] = []
    kinds = list(leads)
    for position, kind in enumerate(kinds):
        used = sum(words(sentence) for sentence in sentences)
        reserved = sum(words(leads[k]) for k in kinds[position:])
        names = _names(
            vocabulary,
            state.troubled.get(kind, []),
            state.trouble_count(kind),
            MAX_WORDS - used - reserved,
        )
        sentences.append(f"{leads[kind]}: {names}." if names else f"{leads[kind]}.")
    return " ".join(sentences)
