"""How the skill names robots and zones, and how it maps what a person said to their ids.

Everything comes from fleet.yaml: a robot is called by its first spoken name ("placebot
one"), a zone by the spoken name that reads well in a sentence ("zone A", "the loading
zone"), and the whole fleet by the `all` group's names.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.protocol import FLEET_GROUP, FLEET_GROUP_NAMES
from vahr.protocol.text import normalize

if TYPE_CHECKING:
    from vahr.protocol import Fleet, Zone

# The ROBOT slot value (and target) that means every robot; it matches the generator's id.
FLEET = FLEET_GROUP
DEFAULT_FLEET_NAMES = FLEET_GROUP_NAMES
# Packages are picked up here, so it is never a delivery destination.
LOADING = "LOADING"


def _upper_letters(name: str) -> str:
    # "zone a" must be spoken as the letter, so single letters become capitals.
    return " ".join(word.upper() if len(word) == 1 else word for word in name.split())


def zone_phrase(zone: Zone) -> str:
    """The zone's name as it reads inside a sentence: "zone A", "the loading zone"."""
    names = [normalize(name) for name in zone.spoken]
    with_zone = [name for name in names if "zone" in name.split()]
    preferred = [name for name in with_zone if name.startswith("the ")] or with_zone
    if preferred:
        return _upper_letters(preferred[0])
    if len(zone.id) <= 2:
        return f"zone {zone.id}"
    return _upper_letters(names[0] if names[0].startswith("the ") else f"the {names[0]}")


def capitalise(sentence: str) -> str:
    return sentence[:1].upper() + sentence[1:]


def join_choices(names: list[str]) -> str:
    """'a', 'a or b', 'a, b, or c'."""
    if len(names) <= 2:
        return " or ".join(names)
    return ", ".join(names[:-1]) + ", or " + names[-1]


class Vocabulary:
    """Spoken names of the fleet's robots and zones, both ways."""

    def __init__(self, fleet: Fleet) -> None:
        self.fleet = fleet
        group = next((group for group in fleet.groups if group.id == FLEET_GROUP), None)
        self.fleet_names = tuple(group.spoken) if group else DEFAULT_FLEET_NAMES
        self._robot_ids: dict[str, str] = {FLEET: FLEET}
        for name in self.fleet_names:
            self._robot_ids[normalize(name)] = FLEET
        for robot in fleet.robots:
            self._robot_ids[robot.thing.lower()] = robot.thing
            for name in robot.spoken:
                self._robot_ids[normalize(name)] = robot.thing
        self._zone_ids: dict[str, str] = {}
        self._zone_names: dict[str, str] = {}
        for zone in fleet.zones:
            self._zone_ids[zone.id.lower()] = zone.id
            for name in zone.spoken:
                self._zone_ids[normalize(name)] = zone.id
            self._zone_names[zone.id] = zone_phrase(zone)

    @property
    def robot_ids(self) -> tuple[str, ...]:
        """Every valid ROBOT id: the things and the fleet."""
        return (*self.fleet.robot_things, FLEET)

    def robot(self, thing: str) -> str:
        """What to call a robot (or the fleet) in speech, in lower case."""
        if thing == FLEET:
            return normalize(self.fleet_names[0])
        return normalize(self.fleet.spoken_name(thing))

    def zone(self, zone_id: str) -> str:
        return self._zone_names.get(zone_id, f"zone {zone_id}")

    def robot_id(self, heard: str) -> str | None:
        """The id for a spoken robot name (or thing name), if the fleet has one."""
        return self._robot_ids.get(normalize(heard))

    def zone_id(self, heard: str) -> str | None:
        return self._zone_ids.get(normalize(heard))

    def robot_choices(self, *, include_fleet: bool = True) -> str:
        names = [self.robot(thing) for thing in self.fleet.robot_things]
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
