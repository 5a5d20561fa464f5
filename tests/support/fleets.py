"""Fleet files for tests, under tests/fleets/, loaded by name, and what each broken one must
say: the one line a command prints after `error: FILE: `."""

from __future__ import annotations

from pathlib import Path

FLEETS_DIR = Path(__file__).resolve().parents[1] / "fleets"
# Six made-up robots (birds) in a bakery, with a group besides the whole fleet.
SIX_ROBOTS = FLEETS_DIR / "six_robots.yaml"
# Four robots in a small hospital, with places named as staff say them and German names.
HOSPITAL = FLEETS_DIR / "hospital.yaml"
# Three rovers and one charger: batteries, charging and robots out of service.
THREE_ROVERS = FLEETS_DIR / "three_rovers.yaml"

# tests/fleets/bad/NAME.yaml -> the error, naming the entry and the reason.
BAD_FLEETS = {
    "duplicate_thing": "robots.2.thing: 'rover1' is used twice (also robots.0.thing)",
    "duplicate_spoken_name": (
        "robots.1.spoken.1: 'the first rover' is used twice (also robots.0.spoken.1)"
    ),
    "duplicate_zone": "zones.2.id: 'NORTH' is used twice (also zones.1.id)",
    "group_unknown_robot": (
        "groups.0.robots.1: 'rover9' is not a robot of the fleet; robots are rover1, rover2"
    ),
    "group_zone_member": (
        "groups.0.robots.1: 'NORTH' is a zone, not a robot of the fleet; robots are rover1, rover2"
    ),
    "zone_outside_floor": (
        "zones.1.pose: (5, 8) is outside the floor (x 0 to 10, y 0 to 6), so no robot can reach it"
    ),
    "start_outside_floor": (
        "robots.1.start: (-1.5, 3) is outside the floor (x 0 to 10, y 0 to 10), "
        "so the robot cannot start there"
    ),
    "not_yaml": (
        "is not valid YAML (while parsing a flow sequence at line 2, column 9 did not find "
        "expected ',' or ']' at line 3, column 1)"
    ),
    "empty": "is empty; a fleet needs robots: and zones:",
    "battery_without_charger": (
        "zones: no zone has charger: true, but batteries drain (battery:); add a charging "
        "zone, or set the drain rates of battery.types to 0"
    ),
}


def bad_fleet(name: str) -> Path:
    return FLEETS_DIR / "bad" / f"{name}.yaml"
