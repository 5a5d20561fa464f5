"""The fleet file's battery rules: defaults, robot types, and one line naming the field
for a file whose rules cannot hold (a reserve above the threshold, an unknown type,
batteries that drain with nowhere to charge)."""

from __future__ import annotations

from pathlib import Path

import pytest

from vahr.cli import main as vahr_main
from vahr.domain import Fleet, load_fleet
from vahr.domain.battery import NO_DRAIN, BatteryType
from vahr.protocol import ProtocolError

ROVERS = Path(__file__).parents[1] / "fleets" / "three_rovers.yaml"
BASE = """
robots:
  - {thing: r1, spoken: [r one], start: {x: 0, y: 0}, type: TYPE}
zones:
  - {id: LOADING, spoken: [loading], pose: {x: 1, y: 1}}
  - {id: DOCK, spoken: [dock], pose: {x: 2, y: 2}, charger: CHARGER}
"""


def fleet(battery: str, *, robot_type: str = "standard", charger: bool = True) -> Fleet:
    text = BASE.replace("TYPE", robot_type).replace("CHARGER", str(charger).lower())
    return Fleet.from_yaml(battery + text)


def test_a_fleet_without_a_battery_section_never_drains() -> None:
    bundled = load_fleet()
    assert not bundled.batteries_drain
    assert bundled.battery_rates("placebot1") == NO_DRAIN
    assert bundled.battery_plan.charge_below == 20 and bundled.battery_plan.reserve == 10


def test_the_rovers_drain_by_their_type_and_have_one_charger() -> None:
    rovers = load_fleet(ROVERS)
    assert rovers.batteries_drain
    assert rovers.battery_rates("rover1") == BatteryType(
        drain_per_m=0.05, idle_drain_per_h=2, working_drain_per_h=4, charge_per_h=400
    )
    assert [zone.id for zone in rovers.chargers] == ["DOCK"]


def test_a_battery_section_without_types_drains_at_the_typical_rates() -> None:
    typical = fleet("battery: {}\n")
    assert typical.battery_rates("r1") == BatteryType()
    assert typical.battery_plan.charged == 90


@pytest.mark.parametrize(
    ("battery", "kwargs", "field", "words"),
    [
        ("battery: {reserve: 25}\n", {}, "battery.reserve", "must be below"),
        ("battery: {charged: 15}\n", {}, "battery.charged", "must be above"),
        ("battery: {charge_below: 120}\n", {}, "battery.charge_below", "100"),
        ("battery: {reserve: -1}\n", {}, "battery.reserve", "0"),
        (
            "battery: {types: {heavy: {}}}\n",
            {"robot_type": "light"},
            "robots.0.type",
            "'light' is not a type of battery.types (heavy)",
        ),
        ("battery: {}\n", {"charger": False}, "zones", "no zone has charger: true"),
        ("battery: {types: {standard: {drain_per_m: -1}}}\n", {}, "drain_per_m", "0"),
    ],
)
def test_rules_that_cannot_hold_are_one_line_naming_the_field(
    battery: str, kwargs: dict[str, object], field: str, words: str
) -> None:
    with pytest.raises(ProtocolError) as caught:
        fleet(battery, **kwargs)  # type: ignore[arg-type]
    message = str(caught.value)
    assert "\n" not in message
    assert field in message and words in message


def test_batteries_that_never_drain_need_no_charger() -> None:
    still = "battery: {types: {standard: {drain_per_m: 0, idle_drain_per_h: 0, working_drain_per_h: 0}}}\n"
    assert not fleet(still, charger=False).batteries_drain


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["battery", "120"], "battery 120: a charge is 0 to 100 percent"),
        (["battery", "-3"], "a charge is 0 to 100 percent"),
        (["battery", "full"], "not a number"),
        (["battery"], "battery needs the charge to set"),
        (["stuck", "40"], "only a battery fault takes a percent"),
    ],
)
def test_vahr_fault_battery_refuses_a_charge_that_is_not_one_before_sending(
    argv: list[str], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    # No stack runs on this port: the error comes before anything is sent.
    code = vahr_main(["fault", "rover1", *argv, "--api", "http://127.0.0.1:9"])
    err = capsys.readouterr().err.strip()
    assert code != 0
    assert words in err and "\n" not in err


def test_a_charger_no_robot_can_reach_is_one_line() -> None:
    text = """
battery: {}
floor: {width: 10, height: 6}
robots:
  - {thing: r1, spoken: [r one], start: {x: 1, y: 1}}
zones:
  - {id: LOADING, spoken: [loading], pose: {x: 2, y: 2}}
  - {id: DOCK, spoken: [dock], pose: {x: 14, y: 2}, charger: true}
"""
    with pytest.raises(ProtocolError) as caught:
        Fleet.from_yaml(text)
    assert str(caught.value) == (
        "zones.1.pose: (14, 2) is outside the floor (x 0 to 10, y 0 to 6), so no robot can reach it"
    )
