"""What a person hears is spoken names only, as the fleet file writes them: a zone by its
first spoken form ("ward three", not "the ward three"), a robot's reason with the zone it
names by id said by its name, and a robot between zones placed by the nearest one."""

from __future__ import annotations

from typing import Any

import pytest

from skill.robots import ShadowRead
from skill.speech import robot_status
from skill.vocabulary import Vocabulary
from tests.support.fleets import HOSPITAL, SIX_ROBOTS
from vahr.domain import load_fleet
from vahr.domain.fleet import reason_said, zone_phrase
from vahr.protocol import LastCommand, Reported, ReportedPose, RobotShadow


@pytest.fixture(scope="module")
def hospital() -> Vocabulary:
    return Vocabulary(load_fleet(HOSPITAL))


def read(thing: str, **state: Any) -> ShadowRead:
    return ShadowRead(thing, RobotShadow(reported=Reported(**{"connected": True, **state})))


def test_a_zone_is_said_as_the_fleet_file_writes_its_first_name() -> None:
    assert [zone_phrase(zone) for zone in load_fleet(HOSPITAL).zones] == [
        "the dock",
        "the pharmacy",
        "ward three",
        "reception",
        "the lab",
    ]
    # "the" only where the file writes the name with it too
    assert [zone_phrase(zone) for zone in load_fleet(SIX_ROBOTS).zones] == [
        "the mill",
        "the pantry",
        "the oven",
        "the shop",
    ]


@pytest.mark.parametrize(
    ("state", "spoken"),
    [
        (
            {
                "status": "error",
                "last_command": LastCommand(
                    "c1", "navigate", "failed", "goal to PHARMACY aborted: an injected fault",
                    "PHARMACY",
                ),
            },
            "Iris has a problem: goal to the pharmacy aborted: an injected fault.",
        ),
        (
            {
                "status": "stuck",
                "last_command": LastCommand(
                    "c2", "navigate", "failed", "stuck: no progress towards LAB for 10 s", "LAB"
                ),
            },
            "Iris is stuck on its way to the lab.",
        ),
        # Between zones: the nearest one (the lab stands at 14, 1)
        ({"status": "idle", "pose": ReportedPose(12.0, 2.0, 0.0)}, "Iris is idle near the lab."),
        (
            {"status": "stopped", "pose": ReportedPose(2.5, 5.0, 0.0)},
            "Iris is stopped near the dock.",
        ),
        (
            {"status": "idle", "connected": False, "pose": ReportedPose(13.0, 5.5, 0.0)},
            "Iris seems to be offline; it was last seen near ward three.",
        ),
        ({"status": "idle", "zone": "WARD_THREE"}, "Iris is idle in ward three."),
    ],
)  # fmt: skip
def test_status_says_places_by_their_names(
    hospital: Vocabulary, state: dict[str, Any], spoken: str
) -> None:
    assert robot_status(hospital, read("iris", **state)) == spoken


def test_a_reason_names_its_zone_by_name_once() -> None:
    assert reason_said("goal to WARD_THREE aborted", "WARD_THREE", "ward three") == (
        "goal to ward three aborted"
    )
    # The name already said is left alone; another id, or a part of a word, is not touched
    assert reason_said("no path to zone A", "A", "zone A") == "no path to zone A"
    assert reason_said("goal to A aborted", "A", "zone A") == "goal to zone A aborted"
    assert reason_said("LABEL of LAB_2 near LAB", "LAB", "the lab") == "LABEL of LAB_2 near the lab"
    assert reason_said("goal to LAB aborted", None, "the lab") == "goal to LAB aborted"
