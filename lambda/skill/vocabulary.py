"""How the skill names robots and zones, and how it maps what a person said to their ids.

Everything comes from fleet.yaml: a robot is called by its first spoken name ("placebot
one"), a zone by the spoken name that reads well in a sentence ("zone A", "the loading
zone"), and the whole fleet by the `all` group's names. In another locale than en-US the
names are those of `spoken_by_locale` (`vahr.domain.fleet.spoken_in`), read for the
request's locale (`skill.catalog`): "placebot eins", "Zone A", "Ladezone". Names heard are
looked up in every language the fleet file gives.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import prompts
from skill.catalog import current_locale
from vahr.domain import FLEET_GROUP, FLEET_GROUP_NAMES
from vahr.domain.fleet import (
    SPOKEN_LOCALE,
    names_by_locale,
    reason_said,
    spoken_in,
    zone_name_in,
    zone_phrase,
)
from vahr.domain.locale import SUPPORTED_LOCALES, load_language
from vahr.domain.text import normalize

if TYPE_CHECKING:
    from vahr.domain import Fleet, Group, Robot, Zone

# The ROBOT slot value (and target) that means every robot; it matches the generator's id.
FLEET = FLEET_GROUP
DEFAULT_FLEET_NAMES = FLEET_GROUP_NAMES
# Packages are picked up here, so it is never a delivery destination.
LOADING = "LOADING"
# The ICAO spelling alphabet, by letter: radio operators say "bravo" for B because the
# letters' own names (B, C, D, E...) are the hardest words for a listener to tell apart.
SPELLING_ALPHABET = {
    word[0]: word
    for word in (
        "alpha bravo charlie delta echo foxtrot golf hotel india juliett kilo lima mike "
        "november oscar papa quebec romeo sierra tango uniform victor whiskey x-ray yankee zulu"
    ).split()
}


def capitalise(sentence: str) -> str:
    return sentence[:1].upper() + sentence[1:]


def count_text(number: int) -> str:
    """A count in digits as the request's language writes it for the speech engine: "1,000"
    in English, "1.000" in German (whose comma is the decimal point: "1,000" is one)."""
    return f"{number:,}".replace(",", prompts.THOUSANDS_SEPARATOR)


# A fleet of more robots than this is not listed one by one when the skill asks which robot
# (each name is a few words, and a question should stay short enough to hear).
ROBOT_CHOICES_MAX = 6
ROBOT_CHOICES_SHOWN = 3


def join_choices(names: list[str]) -> str:
    """'a', 'a or b', 'a, b, or c' (in German 'a, b oder c')."""
    word = prompts.OR
    if len(names) <= 2:
        return f" {word} ".join(names)
    serial = "," if current_locale() == SPOKEN_LOCALE else ""
    return ", ".join(names[:-1]) + f"{serial} {word} " + names[-1]


class Vocabulary:
    """Spoken names of the fleet's robots and zones, both ways."""

    def __init__(self, fleet: Fleet) -> None:
        self.fleet = fleet
        group = next((group for group in fleet.groups if group.id == FLEET_GROUP), None)
        self.fleet_names = tuple(group.spoken) if group else DEFAULT_FLEET_NAMES
        self._robot_ids: dict[str, str] = {FLEET: FLEET}
        for name in self.fleet_names:
            self._robot_ids[normalize(name)] = FLEET
        if group is None:
            # Without a group `all`, each language's own words for the whole fleet.
            for locale in SUPPORTED_LOCALES:
                for name in load_language(locale).fleet_names:
                    self._robot_ids.setdefault(normalize(name), FLEET)
        self._group = group
        for robot in fleet.robots:
            self._robot_ids[robot.thing.lower()] = robot.thing
            for name in _every_name(robot):
                self._robot_ids.setdefault(normalize(name), robot.thing)
        if group is not None:
            for name in _every_name(group):
                self._robot_ids.setdefault(normalize(name), FLEET)
        self._zone_ids: dict[str, str] = {}
        self._zone_names: dict[str, str] = {}
        for zone in fleet.zones:
            self._zone_ids[zone.id.lower()] = zone.id
            for name in _every_name(zone):
                self._zone_ids.setdefault(normalize(name), zone.id)
            self._zone_names[zone.id] = zone_phrase(zone)

    @property
    def robot_ids(self) -> tuple[str, ...]:
        """Every valid ROBOT id: the things and the fleet."""
        return (*self.fleet.robot_things, FLEET)

    def robot(self, thing: str) -> str:
        """What to call a robot (or the fleet) in speech, in lower case."""
        locale = current_locale()
        if thing == FLEET:
            if locale != SPOKEN_LOCALE:
                names = (
                    spoken_in(self._group, locale)
                    if self._group is not None
                    else load_language(locale).fleet_names
                )
                return normalize(names[0])
            return normalize(self.fleet_names[0])
        return normalize(self.fleet.spoken_name(thing, locale))

    def zone(self, zone_id: str) -> str:
        locale = current_locale()
        if locale != SPOKEN_LOCALE and zone_id in self.fleet.zone_ids:
            return zone_name_in(self.fleet.zone(zone_id), locale)
        return self._zone_names.get(zone_id, f"zone {zone_id}")

    def reason(self, reason: str, zone_id: str | None) -> str:
        """A robot's reason as said: the zone it names by id (`zone_id`, the zone the
        command was for) by its spoken name, in the request's language."""
        return reason_said(reason, zone_id, self.zone(zone_id)) if zone_id else reason

    def spelled(self, zone_id: str) -> str | None:
        """The spelling-alphabet word a zone named by a letter answers to ("bravo" for
        zone B), when the fleet file lists it among the zone's names in this language."""
        zone = next((zone for zone in self.fleet.zones if zone.id == zone_id), None)
        if zone is None:
            return None
        names = {normalize(name) for name in spoken_in(zone, current_locale())}
        letters = {name.split()[-1] for name in names if len(name.split()[-1]) == 1}
        words = [SPELLING_ALPHABET.get(letter) for letter in sorted(letters)]
        return next((word for word in words if word in names), None)

    def robot_id(self, heard: str) -> str | None:
        """The id for a spoken robot name (or thing name), if the fleet has one."""
        return self._robot_ids.get(normalize(heard))

    def zone_id(self, heard: str) -> str | None:
        return self._zone_ids.get(normalize(heard))

    def robot_choices(self, *, include_fleet: bool = True) -> str:
        things = self.fleet.robot_things
        if len(things) > ROBOT_CHOICES_MAX:
            # A thousand names are minutes of speech: a few, then how to name the others.
            names = [self.robot(thing) for thing in things[:ROBOT_CHOICES_SHOWN]]
            count = count_text(len(things))
            return join_choices([*names, prompts.ANOTHER_ROBOT.format(count=count)])
        names = [self.robot(thing) for thing in things]
        if include_fleet and len(names) > 1:
            names.append(self.robot(FLEET))
        return join_choices(names)

    def zone_choices(self, *, deliverable: bool = False) -> str:
        """The zones to choose from; `deliverable` leaves out the loading zone."""
        zone_ids = [z for z in self.fleet.zone_ids if not (deliverable and z == LOADING)]
        return join_choices([self.zone(zone_id) for zone_id in zone_ids])

    def examples(self) -> dict[str, str]:
        """Real names for example sentences: two robots and two delivery zones."""
        things = self.fleet.robot_things
        zones = [zone for zone in self.fleet.zone_ids if zone != LOADING] or list(
            self.fleet.zone_ids
        )
        return {
            "robot": self.robot(things[0]),
            "other": self.robot(things[1 % len(things)]),
            "zone": self.zone(zones[0]),
            "other_zone": self.zone(zones[1 % len(zones)]),
        }


def _every_name(entry: Robot | Zone | Group) -> list[str]:
    """A robot's, zone's or group's names in every language the fleet file gives."""
    return [*entry.spoken, *(name for names in names_by_locale(entry).values() for name in names)]
