"""Status and outcome speech from shadows: pure functions, no AWS."""

from __future__ import annotations

from typing import Any

import pytest

from skill.acknowledgment import RobotAnswer, classify
from skill.commands import publication, sequential
from skill.robots import ShadowRead
from skill.speech import command_report, robot_status, sequential_report, status_report
from skill.vocabulary import FLEET, Vocabulary, zone_phrase
from vahr.domain import Fleet
from vahr.protocol import LastCommand, Reported, RobotShadow


@pytest.fixture(scope="module")
def words(fleet: Fleet) -> Vocabulary:
    return Vocabulary(fleet)


def read(thing: str = "placebot1", **state: Any) -> ShadowRead:
    return ShadowRead(thing, RobotShadow(reported=Reported(**{"connected": True, **state})))


@pytest.mark.parametrize(
    ("state", "spoken"),
    [
        ({"status": "idle", "zone": "LOADING"}, "Placebot one is idle in the loading zone."),
        ({"status": "idle"}, "Placebot one is idle."),
        (
            {"status": "idle", "zone": "C", "connected": False},
            "Placebot one seems to be offline; it was last seen in zone C.",
        ),
        ({"connected": False}, "Placebot one seems to be offline."),
        (
            {"status": "navigating", "cargo": True, "destination": "B", "task": "deliver"},
            "Placebot one is carrying a package to zone B.",
        ),
        (
            {"status": "navigating", "destination": "LOADING", "task": "deliver"},
            "Placebot one is on its way to the loading zone to pick up a package.",
        ),
        (
            {"status": "navigating", "destination": "D", "task": "sequential_delivery"},
            "Placebot one is on its way to pick up a package for zone D.",
        ),
        (
            {"status": "navigating", "destination": "A", "task": "navigate"},
            "Placebot one is on its way to zone A.",
        ),
        ({"status": "navigating"}, "Placebot one is moving."),
        (
            {"status": "loading", "zone": "LOADING"},
            "Placebot one is being loaded in the loading zone.",
        ),
        ({"status": "unloading", "zone": "B"}, "Placebot one is being unloaded in zone B."),
        (
            {"status": "waiting", "task": "weather_delivery"},
            "Placebot one is waiting to hear the weather.",
        ),
        (
            {"status": "waiting", "task": "sequential_delivery", "destination": "B"},
            "Placebot one is waiting for its turn to deliver to zone B.",
        ),
        ({"status": "waiting"}, "Placebot one is waiting."),
        ({"status": "stopped", "zone": "A"}, "Placebot one is stopped in zone A."),
        ({"status": "stopped"}, "Placebot one is stopped."),
        ({"status": "stuck", "destination": "C"}, "Placebot one is stuck on its way to zone C."),
        ({"status": "stuck"}, "Placebot one is stuck."),
        (
            {
                "status": "error",
                "last_command": LastCommand("c1", "navigate", "failed", "lidar offline."),
            },
            "Placebot one has a problem: lidar offline.",
        ),
        ({"status": "error"}, "Placebot one has a problem."),
    ],
)
def test_robot_status_sentence(words: Vocabulary, state: dict[str, Any], spoken: str) -> None:
    assert robot_status(words, read(**state)) == spoken


def test_status_report_joins_robots_in_fleet_order(words: Vocabulary) -> None:
    reads = [read("placebot1", status="idle", zone="A"), ShadowRead("placebot2")]
    assert status_report(words, reads) == (
        "Placebot one is idle in zone A. Placebot two has not reported yet."
    )


def test_zone_names_read_well_in_a_sentence(fleet: Fleet) -> None:
    assert [zone_phrase(zone) for zone in fleet.zones] == [
        "the loading zone",
        "zone A",
        "zone B",
        "zone C",
        "zone D",
    ]


def test_vocabulary_resolves_spoken_names_and_lists_choices(words: Vocabulary) -> None:
    assert words.robot_id("Place Bot Two") == "placebot2"
    assert words.robot_id("everybody") == FLEET
    assert words.robot_id("the blue robot") is None
    assert words.zone_id("Charlie") == "C"
    assert words.robot_choices() == "placebot one, placebot two, or all robots"
    assert words.robot_choices(include_fleet=False) == "placebot one or placebot two"


def answer(
    thing: str,
    command_id: str,
    result: str | None,
    reason: str | None = None,
    connected: bool = True,
) -> RobotAnswer:
    last = LastCommand(command_id, "navigate", result, reason) if result else None  # type: ignore[arg-type]
    shadow = RobotShadow(reported=Reported(connected=connected, last_command=last))
    return classify(thing, command_id, shadow) or RobotAnswer(
        thing, command_id, "unconfirmed", shadow=shadow
    )


def test_an_older_command_id_is_not_an_acknowledgment() -> None:
    shadow = RobotShadow(reported=Reported(last_command=LastCommand("old", "navigate", "accepted")))
    assert classify("placebot1", "new", shadow) is None


def test_a_done_command_counts_as_acknowledged() -> None:
    assert answer("placebot1", "c", "done").confirmed


def test_fleet_of_three_speaks_all_robots(words: Vocabulary) -> None:
    three = Fleet.from_yaml(
        "robots:\n"
        + "".join(
            f"  - {{thing: r{n}, spoken: [robot {word}], start: {{x: 0, y: {n}}}}}\n"
            for n, word in ((1, "one"), (2, "two"), (3, "three"))
        )
        + "zones:\n  - {id: LOADING, spoken: [loading zone], pose: {x: 0, y: 0}}\n"
        + "  - {id: A, spoken: [zone a], pose: {x: 5, y: 0}}\n"
    )
    vocabulary = Vocabulary(three)
    item = publication(three, "navigate", FLEET, {"zone": "A"})
    answers = {thing: answer(thing, item.command.id, "accepted") for thing in three.robot_things}
    assert command_report(vocabulary, item, answers) == "All 3 robots are on their way to zone A."
    answers["r3"] = answer("r3", item.command.id, None, connected=False)
    answers["r2"] = answer("r2", item.command.id, "failed", "bumper pressed")
    assert command_report(vocabulary, item, answers) == (
        "1 of 3 robots confirmed; robot two failed: bumper pressed; "
        "robot three did not answer and seems to be offline."
    )


def test_sequential_report_names_what_went_wrong(fleet: Fleet, words: Vocabulary) -> None:
    items = sequential(fleet, "placebot1", "A", "placebot2", "B")
    answers = {
        "placebot1": answer("placebot1", items[0].command.id, "accepted"),
        "placebot2": answer("placebot2", items[1].command.id, "rejected", "no cargo bay"),
    }
    assert sequential_report(words, items, answers) == (
        "Only part of the sequential delivery was confirmed: Placebot one will deliver to "
        "zone A first. Placebot two refused the command: no cargo bay."
    )
    answers["placebot1"] = answer("placebot1", items[0].command.id, None)
    answers["placebot2"] = answer("placebot2", items[1].command.id, "accepted")
    assert sequential_report(words, items, answers) == (
        "Only part of the sequential delivery was confirmed: I sent the command, but "
        "placebot one did not confirm it in time. Placebot two will deliver to zone B once "
        "placebot one has delivered."
    )


def test_every_action_has_an_acknowledgment_sentence() -> None:
    from skill import prompts
    from vahr.protocol import ACTIONS

    assert set(ACTIONS) <= prompts.ACKNOWLEDGED.keys()
    assert set(ACTIONS) <= prompts.FLEET_ACKNOWLEDGED.keys()
