"""What the paper's tasks need from a fleet, said in one line before anything runs, and the
demo's scenario in another fleet's names."""

from __future__ import annotations

import pytest

from tests.support.fleets import SIX_ROBOTS
from vahr.commands.demo import script_for
from vahr.commands.fleet_flag import read_fleet
from vahr.domain import Fleet
from vahr.experiment.tasks import UnfitFleet, draw_plan, require_fit_fleet

# The paper's zones under other names, and two robots that are not placebots.
FIT = """
robots:
  - {thing: tug1, spoken: [tug one], start: {x: 1, y: 1}}
  - {thing: tug2, spoken: [tug two], start: {x: 1, y: 2}}
zones:
  - {id: LOADING, spoken: [the dock], pose: {x: 2, y: 2}, arm: loader}
  - {id: A, spoken: [aisle one], pose: {x: 8, y: 6}, arm: unloader}
  - {id: C, spoken: [aisle three], pose: {x: 8, y: 4}, arm: unloader}
  - {id: D, spoken: [aisle four], pose: {x: 8, y: 2}, arm: unloader}
  - {id: E, spoken: [the office], pose: {x: 4, y: 6}}
"""


def test_a_fleet_without_the_papers_zones_is_refused_in_one_line() -> None:
    with pytest.raises(UnfitFleet) as raised:
        require_fit_fleet(read_fleet(SIX_ROBOTS))
    assert str(raised.value) == (
        "the paper's tasks need two robots and delivery zones A, C and D (zones with arm: "
        "unloader); this fleet lacks delivery zones A, C and D"
    )


def test_one_robot_and_a_zone_without_its_arm_are_both_named() -> None:
    one_robot = Fleet.from_yaml(
        FIT.replace("  - {thing: tug2, spoken: [tug two], start: {x: 1, y: 2}}\n", "").replace(
            "pose: {x: 8, y: 2}, arm: unloader", "pose: {x: 8, y: 2}"
        )
    )
    with pytest.raises(UnfitFleet, match=r"this fleet lacks delivery zone D and a second robot$"):
        draw_plan(one_robot, 1)


def test_the_demo_speaks_the_papers_scenario_in_the_fleets_names(fleet: Fleet) -> None:
    # Given a fleet with the paper's zones under other names
    script = script_for(Fleet.from_yaml(FIT))
    lines = [step.utterance for step in script]
    # Then each line names its robots and zones as that fleet does, B being another zone
    assert lines[1:6] == [
        "send tug one to the office",
        "send all robots to the dock",
        "where is tug two",
        "have tug two deliver a package to aisle four",
        "tug one deliver to aisle one then tug two deliver to aisle three",
    ]
    assert script[5].until == (("tug1", "delivered"), ("tug2", "delivered"))
    # and the paper's fleet hears the paper's own script
    assert script_for(fleet)[1].utterance == "send robot one to zone b"
