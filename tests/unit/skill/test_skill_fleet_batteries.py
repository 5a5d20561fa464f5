"""Batteries of a large fleet by voice: "which robots are below thirty percent", "which
robots are low on battery" and "how much battery do the robots have" answered for 300
robots by fleet indexing (a range on the indexed charge, counts), not one shadow read.

The robots' shadows are in a local shadow store behind the local data plane, so the
skill's boto3 `iot` client makes the real fleet-indexing calls (`SearchIndex`,
`GetStatistics`) that it makes on AWS; the index answers them as AWS documents.
"""

from __future__ import annotations

import copy
import json
from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import speech

from tests.conftest import load_event
from vahr.local.robots import generated_fleet, write_fleet
from vahr.protocol import Battery, Reported
from vahr.twin.dataplane import DataPlane, DataPlaneServer
from vahr.twin.meter import Meter
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

SIZE = 300
# rover -> (percent, charging, connected); every other rover has 60 to 99 percent.
LOW = {5: (3, False, True), 17: (8, True, True), 7: (12, False, False), 230: (15, False, True),
       100: (19, False, True), 101: (20, False, True)}  # fmt: skip


@pytest.fixture(scope="module")
def plane() -> Iterator[tuple[Meter, str]]:
    store = ShadowStore()
    for number in range(1, SIZE + 1):
        percent, charging, connected = LOW.get(number, (60 + number % 40, False, True))
        state = Reported(status="idle", connected=connected,
                         battery=Battery(percent=percent, charging=charging))  # fmt: skip
        store.update(f"rover{number}", None, state.to_payload(), commit=False)
    store.commit()
    dataplane = DataPlane(ShadowService(store, lambda _t, _p: None), lambda *_: None, Meter())
    with DataPlaneServer(dataplane, 0) as server:
        yield dataplane.meter, server.url


@pytest.fixture
def skill(
    plane: tuple[Meter, str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> Callable[[dict[str, Any], Any], dict[str, Any]]:
    from skill.app import make_lambda_handler
    from skill.config import SkillConfig

    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "testing")
    monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "testing")
    fleet_file = write_fleet(generated_fleet(SIZE), tmp_path / "fleet.yaml")
    return make_lambda_handler(SkillConfig(data_endpoint=plane[1], fleet_file=str(fleet_file)))


def asked(*, percent: str | None = None, every: bool = False, locale: str = "en-US") -> Any:
    """BatteryIntent as Alexa sends it: "which robots are below {percent} percent", "which
    robots are low on battery" (no slot), "how much battery do all robots have"."""
    event = copy.deepcopy(load_event("alexa_navigate_fleet"))
    event["request"]["locale"] = locale
    intent = event["request"]["intent"]
    intent["name"] = "BatteryIntent"
    slots = {"robot": intent["slots"]["robot"]} if every else {}
    if percent is not None:
        slots["percent"] = {"name": "percent", "value": percent, "confirmationStatus": "NONE"}
    intent["slots"] = slots
    return event


def test_which_robots_are_below_a_percent_names_the_lowest_without_reading_a_shadow(
    skill: Callable[[dict[str, Any], Any], dict[str, Any]], plane: tuple[Meter, str]
) -> None:
    meter = plane[0]
    meter.reset()
    # When someone asks which robots are below ten percent, then below twenty
    assert speech(skill(asked(percent="10"), None)) == (
        "Two robots are below 10 percent: rover 5 3 percent and rover 17 8 percent, charging."
    )
    # Then five robots (the offline one too) are counted and the three lowest named
    assert speech(skill(asked(percent="20"), None)) == (
        "Five robots are below 20 percent; the lowest: rover 5 3 percent, rover 17 8 percent, "
        "charging and rover 7 12 percent."
    )
    assert speech(skill(asked(percent="2"), None)) == "No robot is below 2 percent."
    # And the index answered: not one shadow was read
    assert "http.shadow.get" not in json.dumps(meter.snapshot())


def test_low_on_battery_is_the_fleets_threshold(
    skill: Callable[[dict[str, Any], Any], dict[str, Any]],
) -> None:
    # The generated fleet goes to charge below 20 percent (the default)
    assert speech(skill(asked(), None)).startswith("Five robots are below 20 percent;")


def test_past_a_page_of_low_robots_the_count_is_the_index_s_and_the_names_among_them(
    skill: Callable[[dict[str, Any], Any], dict[str, Any]],
) -> None:
    # Robots under 90 percent are more than one page of the index (100)
    said = speech(skill(asked(percent="90"), None))
    expected = sum(1 for n in range(1, SIZE + 1) if LOW.get(n, (60 + n % 40,))[0] < 90)
    assert said.startswith(f"{expected} robots are below 90 percent, among them rover ")


def test_the_whole_fleets_batteries_are_two_counts(
    skill: Callable[[dict[str, Any], Any], dict[str, Any]],
) -> None:
    assert speech(skill(asked(every=True), None)) == (
        "Of 300 robots, 5 are below 20 percent and 1 is charging. The station shows each "
        "robot's charge."
    )
    assert speech(skill(asked(every=True, locale="de-DE"), None)) == (
        "Von 300 Robotern: 5 haben weniger als 20 Prozent und 1 lädt. Die Leitstelle zeigt den "
        "Ladestand jedes Roboters."
    )
