"""What the skill says about batteries and service: one robot's charge (charging, offline,
none reported), the robots below a percent lowest first, the whole fleet's, and what taking
robots out of service did."""

from __future__ import annotations

import pytest

from skill.battery_speech import below, every_battery, one_battery, refused, service_report
from skill.robots import ShadowRead
from skill.vocabulary import Vocabulary
from tests.support.fleets import THREE_ROVERS
from vahr.dispatch import ServiceChange, Task
from vahr.domain import load_fleet
from vahr.protocol import Battery, Reported, RobotShadow


@pytest.fixture(scope="module")
def vocabulary() -> Vocabulary:
    return Vocabulary(load_fleet(THREE_ROVERS))


def read(
    thing: str, percent: int | None, *, charging: bool = False, connected: bool = True
) -> ShadowRead:
    battery = None if percent is None else Battery(percent=percent, charging=charging)
    return ShadowRead(thing, RobotShadow(Reported(connected=connected, battery=battery)))


def test_one_robots_charge_is_a_number(vocabulary: Vocabulary) -> None:
    assert one_battery(vocabulary, read("rover1", 12)) == "Rover one has 12 percent battery."
    assert one_battery(vocabulary, read("rover1", 40, charging=True)) == (
        "Rover one has 40 percent battery and is charging."
    )
    assert one_battery(vocabulary, read("rover1", 40, connected=False)) == (
        "Rover one is offline; it last reported 40 percent battery."
    )
    assert one_battery(vocabulary, read("rover1", None)) == "Rover one does not report its battery."
    assert one_battery(vocabulary, ShadowRead("rover1")) == "Rover one does not report its battery."


def test_the_robots_below_a_percent_lowest_first(vocabulary: Vocabulary) -> None:
    reads = [read("rover1", 25), read("rover2", 80), read("rover3", 8, charging=True)]
    assert below(vocabulary, 30, reads) == (
        "Two robots are below 30 percent: rover three 8 percent, charging and rover one 25 percent."
    )
    assert below(vocabulary, 10, reads) == (
        "One robot is below 10 percent: rover three 8 percent, charging."
    )
    assert below(vocabulary, 5, reads) == "No robot is below 5 percent."
    assert every_battery(vocabulary, reads[:2]) == (
        "The batteries: rover one 25 percent and rover two 80 percent."
    )


def test_what_taking_robots_out_of_service_did(vocabulary: Vocabulary) -> None:
    moved = Task(
        id="t", request="r", kind="deliver", zone="A", pickup="LOADING", status="assigned",
        thing="rover3", created_at="x",
    )  # fmt: skip
    change = ServiceChange(thing="rover1", in_service=False, changed=True, reassigned=[moved])
    assert service_report(vocabulary, [change]) == (
        "Rover one is out of service now and gets no tasks. "
        "The delivery to zone A went to rover three instead."
    )
    again = ServiceChange(thing="rover2", in_service=False, changed=False)
    assert service_report(vocabulary, [again]) == "Rover two was already out of service."
    assert refused(vocabulary, ["rover1", "rover2"]) == (
        "Rover one and rover two are out of service, so I sent nothing."
    )
