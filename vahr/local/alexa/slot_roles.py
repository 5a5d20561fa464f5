"""Giving the slot values found in an utterance to the chosen intent's slots.

An intent with one slot of a type takes the one value of that type. Several values for one
slot are never guessed between: robots listed together ("robot one and robot two", "robot
one, robot two") that make the whole fleet are the fleet (`all`), but robots named in
separate phrases ("robot two arrived, now send robot one") or as alternatives ("robot one
or robot two") are not; of several values the one meant is the only one not turned down,
as an origin or a rejected alternative ("from the loading zone to zone b", "to zone c
instead of zone a", "robot two, not robot one"); anything else ("to zone a or zone b", "to
zone a, no, zone b") stays unresolved, so the skill asks. The sequential delivery has two
robots and two zones: robots in the order spoken unless "after", "once" or "until" puts the
later-named robot first ("robot two goes after robot one"); a zone belongs to the robot
named before it, and a single zone said before both robots or after both applies to both
("robot one and then robot two deliver to zone d"). The fleet is not one of its two robots,
and one robot cannot follow itself: such a robot slot is left for the skill to ask about.
In a fleet of two, "the other robot" after one robot is the other one, and the fleet with
one robot's turn ("both robots to zone d, placebot one first") is both robots in that
order; a robot said to go "second" right after its name goes second; and "there" or "too"
after the robot without a zone sends it where the other goes. The weather delivery's rule
said aloud is `weather_rule`'s.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import pairwise
from typing import TYPE_CHECKING

from vahr.local.alexa.weather_rule import RULE_SLOTS, rule_zones
from vahr.protocol import FLEET_GROUP
from vahr.skill_model.intents import ROBOT_TYPE, SUNNY_ZONE

if TYPE_CHECKING:
    from collections.abc import Mapping, Set

    from vahr.local.alexa.slot_finder import SlotMatch

# English only: these rules serve en-US until the roles tagger (`roles`) does as well there;
# every other locale's roles come from the tagger, and from data.
# Words that say a robot's turn when they follow its name ("placebot one first").
TURNS = {"first": 0, "second": 1, "last": 1}
# The verbs that may stand between a robot and its turn.
GOING_VERBS = frozenset({"goes", "go", "comes", "delivers", "is", "will", "should"})
# "the other robot": a robot named by the one named before it.
OTHER_ROBOT = ("the", "other")
# Words before a robot that make it the one to go first although it is named second.
_AFTER = frozenset({"after", "once", "until", "till", "for", "behind"})
# Words right before a value that turn it down: where a robot comes from ("from zone a",
# "instead of zone a"), or the value the speaker corrects ("not robot one").
_TURNED_DOWN = frozenset({"from", "of", "not"})
# The only words that may stand between robots listed together as one group ("robot one and
# robot two", "robot one plus robot two", "robot one as well as robot two"); none at all is a
# list too ("robot one, robot two": punctuation is gone by now).
_LISTED = frozenset({"and", "plus", "also", "as", "well"})
# Words that send the second robot where the first went ("delivers there too").
_SAME_PLACE = frozenset({"there", "too", "also", "same", "well"})


def assign_slots(
    declared: Mapping[str, str],
    matches: list[SlotMatch],
    words: list[str],
    robots: Mapping[str, str],
    fleet_name: str,
) -> dict[str, SlotMatch]:
    """Slot name -> the value it takes, for the slots of `declared` (name -> type).

    `robots` are the fleet's robots (id -> name, without the fleet's own id), `fleet_name`
    the fleet value's name."""
    by_type: dict[str, list[str]] = {}
    for name, slot_type in declared.items():
        by_type.setdefault(slot_type, []).append(name)
    if _is_sequence(by_type):
        return _sequence(by_type, matches, words, robots)
    fleet_robots = robots.keys()
    filled: dict[str, SlotMatch] = {}
    rule = set(RULE_SLOTS.values())
    if rule <= declared.keys():
        zone_type = declared[SUNNY_ZONE.name]
        filled.update(rule_zones([m for m in matches if m.type == zone_type], words))
        by_type = {t: [n for n in names if n not in rule] for t, names in by_type.items()}
    for slot_type, names in by_type.items():
        values = [match for match in matches if match.type == slot_type]
        chosen = _one_each(values, len(names), words, fleet_robots, fleet_name)
        for name, value in zip(names, chosen, strict=False):
            if value is not None:
                filled[name] = value
    return filled


def _is_sequence(by_type: Mapping[str, list[str]]) -> bool:
    return [len(names) for names in by_type.values()] == [2, 2]


def _one_each(
    values: list[SlotMatch], slots: int, words: list[str], robots: Set[str], fleet_name: str
) -> list[SlotMatch | None]:
    if not values:
        return []
    if slots > 1 or len(values) == 1 or len({v.id for v in values}) == 1:
        return list(values[:slots])
    return [_merge(values, words, robots, fleet_name)]


def _merge(
    values: list[SlotMatch], words: list[str], robots: Set[str], fleet_name: str
) -> SlotMatch:
    """One value standing for several named where one was expected."""
    ids = {value.id for value in values}
    spoken = " and ".join(value.spoken for value in values)
    first = values[0]
    fleet = ids == set(robots) or ids == {*robots, FLEET_GROUP}
    if first.type == ROBOT_TYPE and fleet and _listed(values, words):
        # Robots named one by one where one robot is expected are all of them only when
        # together they are the fleet, and only when said as one group.
        return replace(first, spoken=spoken, id=FLEET_GROUP, canonical=fleet_name)
    meant = [v for v in values if v.start == 0 or words[v.start - 1] not in _TURNED_DOWN]
    if len(meant) == 1:
        return meant[0]
    return replace(first, spoken=spoken, id=None, canonical=None)


def _listed(values: list[SlotMatch], words: list[str]) -> bool:
    """Whether the values are said as one list: nothing but "and" (or the like) between."""
    return all(
        set(words[before.end : after.start]) <= _LISTED for before, after in pairwise(values)
    )


def _sequence(
    by_type: Mapping[str, list[str]],
    matches: list[SlotMatch],
    words: list[str],
    fleet: Mapping[str, str],
) -> dict[str, SlotMatch]:
    (robot_type, robot_slots), (zone_type, zone_slots) = sorted(
        by_type.items(), key=lambda item: item[0] != ROBOT_TYPE
    )
    # The fleet is not one robot of two: "both robots to zone d" says nothing of the order.
    robots = [m for m in matches if m.type == robot_type and m.id != FLEET_GROUP]
    robots = _the_other_robot(robots, fleet)
    zones = [m for m in matches if m.type == zone_type]
    group = next((m for m in matches if m.type == robot_type and m.id == FLEET_GROUP), None)
    if group is not None and len(robots) == 1 and len(zones) <= 1:
        pair = _pair_from_the_fleet(robots[0], group, words, fleet)
        if pair is not None:
            # "both robots to zone d, placebot one first": the fleet's other robot is the
            # other one, and the zone is both robots'.
            return {
                **dict(zip(robot_slots, pair, strict=True)),
                **{slot: zone for slot in zone_slots for zone in zones},
            }
    # "robot two goes after robot one": the robot named second goes first, and the sentence
    # is about the one named first. A robot said to go "second" before the other goes
    # second too, but says nothing of whose a zone is.
    swapped = len(robots) >= 2 and robots[1].start > 0 and words[robots[1].start - 1] in _AFTER
    if swapped or (len(robots) >= 2 and _turn(robots[0], words, robots[1].start) == 1):
        robots = [robots[1], robots[0], *robots[2:]]
    filled: dict[str, SlotMatch] = dict(zip(robot_slots, robots, strict=False))
    if len(robots) >= 2 and robots[0].id is not None and robots[0].id == robots[1].id:
        # One robot cannot follow itself: the second is asked for, not guessed.
        filled[robot_slots[1]] = replace(robots[1], id=None, canonical=None)
    order = {id(robot): rank for rank, robot in enumerate(robots[:2])}
    owned: dict[int, SlotMatch] = {}
    unowned: list[SlotMatch] = []
    for zone in zones:
        before = [r for r in robots[:2] if r.end <= zone.start]
        owner = max(before, key=lambda r: r.end) if before else None
        after_all = len(robots) >= 2 and len(before) == 2 and len(zones) == 1
        if after_all and swapped:
            owner = robots[1]
        elif owner is None or after_all:
            unowned.append(zone)
            continue
        if order[id(owner)] not in owned:
            owned[order[id(owner)]] = zone
        else:
            unowned.append(zone)
    if len(zones) == 1 and unowned and len(robots) != 1:
        # One zone before or after both robots: both deliver there.
        return {**filled, zone_slots[0]: unowned[0], zone_slots[1]: unowned[0]}
    if len(zones) == 1 and len(owned) == 1 and len(robots) >= 2:
        # "... and then robot two delivers there too": the robot without a zone goes where
        # the other does, when the words after it say so.
        [(rank, zone)] = owned.items()
        missing = 1 - rank
        if set(words[robots[missing].end :]) & _SAME_PLACE:
            owned[missing] = zone
    for rank in range(2):
        if rank not in owned and unowned:
            owned[rank] = unowned.pop(0)
    filled.update({zone_slots[rank]: zone for rank, zone in owned.items()})
    return filled


def _the_other_robot(robots: list[SlotMatch], fleet: Mapping[str, str]) -> list[SlotMatch]:
    """ "the other robot" after one robot of a fleet of two is the fleet's other robot."""
    named = {robot.id for robot in robots if robot.id is not None}
    if len(fleet) != 2 or len(named) != 1:
        return robots
    (other,) = fleet.keys() - named
    return [
        replace(robot, id=other, canonical=fleet[other])
        if robot.id is None
        and tuple(robot.spoken.split()[: len(OTHER_ROBOT)]) == OTHER_ROBOT
        and robot.start > min(r.start for r in robots if r.id is not None)
        else robot
        for robot in robots
    ]


def _turn(robot: SlotMatch, words: list[str], until: int | None = None) -> int | None:
    """The robot's turn when said right after it, before `until` ("placebot one first",
    "placebot two goes second")."""
    after = words[robot.end : min(robot.end + 2, len(words) if until is None else until)]
    if after[:1] and after[0] in GOING_VERBS:
        after = after[1:]
    return TURNS.get(after[0]) if after else None


def _pair_from_the_fleet(
    named: SlotMatch, group: SlotMatch, words: list[str], fleet: Mapping[str, str]
) -> tuple[SlotMatch, SlotMatch] | None:
    """The two robots when the fleet of two and one robot's turn are said ("both robots,
    placebot one first"); None when no turn is said."""
    turn = _turn(named, words)
    if len(fleet) != 2 or named.id not in fleet or turn is None:
        return None
    (other_id,) = fleet.keys() - {named.id}
    other = replace(group, id=other_id, canonical=fleet[other_id])
    return (named, other) if turn == 0 else (other, named)
