"""Status of a large fleet: a summary within the word bound (counts by status, then the
robots in trouble by name and place), the follow-up "which robots are stuck?", and the
reply to a fleet command that names only the few robots that did not confirm.

The large fleet is 1,000 robots of `vahr up --swarm`'s generated fleet, their shadows in a
local shadow store behind the local data plane, so the skill's boto3 `iot` client asks
the real fleet-indexing calls and reads no shadow. The paper's two robots run under moto.
"""

from __future__ import annotations

import copy
import json
from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import speech

from tests.conftest import load_event
from vahr.local.robots import generated_fleet, write_fleet
from vahr.protocol import Reported, ReportedPose
from vahr.twin.dataplane import DataPlane, DataPlaneServer
from vahr.twin.meter import Meter
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from skill_testkit import RobotDoubles

    from vahr.domain import Fleet
    from vahr.protocol.shadow import Status

SIZE = 1000
MAX_WORDS = 60


def _report(store: ShadowStore, thing: str, state: Reported) -> None:
    store.update(thing, None, state.to_payload(), commit=False)


@pytest.fixture(scope="module")
def big_fleet() -> Fleet:
    return generated_fleet(SIZE)


@pytest.fixture(scope="module")
def plane(big_fleet: Fleet) -> Iterator[tuple[ShadowStore, DataPlane, str]]:
    """1,000 robots: 990 idle, 8 driving, rover 17 stuck in zone C, rover 230 stuck on its
    way beside zone A; the local data plane on a free port serving their index."""
    store = ShadowStore()
    zone_a = big_fleet.zone("A").pose
    for number in range(1, SIZE + 1):
        state = Reported(status="idle", zone=None, connected=True)
        if number in range(500, 508):
            state = Reported(status="navigating", destination="B", connected=True)
        _report(store, f"rover{number}", state)
    _report(store, "rover17", Reported(status="stuck", zone="C", connected=True))
    near_a = ReportedPose(zone_a.x - 3.0, zone_a.y + 1.0)
    _report(store, "rover230", Reported(status="stuck", pose=near_a, connected=True))
    store.commit()
    dataplane = DataPlane(ShadowService(store, lambda _t, _p: None), lambda *_: None, Meter())
    with DataPlaneServer(dataplane, 0) as server:
        yield store, dataplane, server.url


@pytest.fixture
def big_skill(
    plane: tuple[ShadowStore, DataPlane, str],
    big_fleet: Fleet,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> Callable[[dict[str, Any], Any], dict[str, Any]]:
    from skill.app import make_lambda_handler
    from skill.config import SkillConfig

    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "testing")
    monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "testing")
    fleet_file = write_fleet(big_fleet, tmp_path / "fleet.yaml")
    config = SkillConfig(data_endpoint=plane[2], fleet_file=str(fleet_file))
    return make_lambda_handler(config)


def _intent(name: str) -> dict[str, Any]:
    event = copy.deepcopy(load_event("alexa_status"))
    event["request"]["intent"]["name"] = name
    if name != "StatusIntent":
        event["request"]["intent"]["slots"] = {}
    return event


def test_status_of_a_thousand_robots_is_a_summary_within_sixty_words(
    big_skill: Callable[[dict[str, Any], Any], dict[str, Any]],
    plane: tuple[ShadowStore, DataPlane, str],
) -> None:
    meter = plane[1].meter
    meter.reset()
    said = speech(big_skill(_intent("StatusIntent"), None))
    assert said == (
        "Of 1,000 robots, 990 are idle, 8 are driving and 2 are stuck: rover 17 in zone C "
        "and rover 230 near zone A."
    )
    assert len(said.split()) <= MAX_WORDS
    # Not one shadow was read: the index answered.
    assert "http.shadow.get" not in json.dumps(meter.snapshot())


def test_in_german_a_thousand_is_written_as_german_reads_it(
    big_skill: Callable[[dict[str, Any], Any], dict[str, Any]],
) -> None:
    # German's comma is its decimal point: "1,000 Robotern" would be read as one robot
    event = _intent("StatusIntent")
    event["request"]["locale"] = "de-DE"
    said = speech(big_skill(event, None))
    assert said.startswith("Von 1.000 Robotern: 990 warten auf Aufträge, 8 fahren")


def test_which_robots_are_stuck_names_them_and_where(
    big_skill: Callable[[dict[str, Any], Any], dict[str, Any]],
) -> None:
    said = speech(big_skill(_intent("ProblemRobotsIntent"), None))
    assert said == "2 robots are stuck: rover 17 in zone C and rover 230 near zone A."


def test_many_in_trouble_are_named_only_as_far_as_the_word_bound_allows(
    plane: tuple[ShadowStore, DataPlane, str],
    big_skill: Callable[[dict[str, Any], Any], dict[str, Any]],
) -> None:
    store = plane[0]
    failed = [f"rover{n}" for n in range(600, 640)]
    offline = [f"rover{n}" for n in range(700, 705)]
    try:
        for thing in failed:
            _report(store, thing, Reported(status="error", zone="D", connected=True))
        for thing in offline:
            _report(store, thing, Reported(status="idle", zone="B", connected=False))
        store.commit()
        summary = speech(big_skill(_intent("StatusIntent"), None))
        problems = speech(big_skill(_intent("ProblemRobotsIntent"), None))
    finally:
        for thing in failed + offline:
            _report(store, thing, Reported(status="idle", connected=True))
        store.commit()
    assert summary.startswith(
        "Of 1,000 robots, 950 are idle, 8 are driving, 40 have failed and 2 are stuck: "
        "rover 17 in zone C and rover 230 near zone A. Failed: rover 600 in zone D"
    )
    assert len(summary.split()) <= MAX_WORDS
    assert problems.startswith(
        "2 robots are stuck: rover 17 in zone C and rover 230 near zone A. 40 robots have "
        "failed: rover 600 in zone D"
    )
    assert " more" in problems
    assert len(problems.split()) <= MAX_WORDS


def test_the_papers_two_robots_still_get_one_sentence_each(
    robots: RobotDoubles, skill: Callable[[dict[str, Any], Any], dict[str, Any]]
) -> None:
    robots.report("placebot2", Reported(status="stuck", destination="C", connected=True))
    said = speech(skill(load_event("alexa_status"), None))
    assert said == (
        "Placebot one is idle in the loading zone. Placebot two is stuck on its way to zone C."
    )
    assert speech(skill(_intent("ProblemRobotsIntent"), None)) == (
        "1 robot is stuck: placebot two."
    )


def test_a_small_fleet_with_nobody_in_trouble_says_so(
    robots: RobotDoubles, skill: Callable[[dict[str, Any], Any], dict[str, Any]]
) -> None:
    assert speech(skill(_intent("ProblemRobotsIntent"), None)) == (
        "No robot is stuck, failed or offline."
    )


def test_a_fleet_command_reply_names_only_the_first_few_unconfirmed() -> None:
    from datetime import UTC, datetime

    from skill.acknowledgment import RobotAnswer
    from skill.commands import Publication
    from skill.speech import command_report
    from skill.vocabulary import FLEET, Vocabulary
    from vahr.protocol import Navigate, ZoneParams

    fleet = generated_fleet(SIZE)
    command = Navigate(
        id="c1", issued_at=datetime.now(UTC), source="alexa", params=ZoneParams(zone="B")
    )
    things = list(fleet.robot_things)
    item = Publication(
        topic="vahr/fleet/cmd", command=command, recipients=tuple(things), target=FLEET
    )
    answers = {
        thing: RobotAnswer(
            thing=thing, command_id="c1", outcome="acknowledged" if i >= 7 else "unconfirmed"
        )
        for i, thing in enumerate(things)
    }
    said = command_report(Vocabulary(fleet), item, answers)
    assert said == (
        "993 of 1,000 robots confirmed; rover 1 did not answer and seems to be offline; "
        "rover 2 did not answer and seems to be offline; rover 3 did not answer and seems to "
        "be offline; and 4 more had not confirmed yet."
    )


@pytest.mark.parametrize("stuck", [0, 1, 3, 40])
@pytest.mark.parametrize("failed", [0, 1, 25])
@pytest.mark.parametrize("offline", [0, 2, 300])
def test_every_mix_of_troubles_stays_within_the_word_bound(
    big_fleet: Fleet, stuck: int, failed: int, offline: int
) -> None:
    from skill.fleet_status import NAMED_MAX, FleetState
    from skill.iot_fleet_index import IndexedRobot
    from skill.speech import fleet_summary, problem_report
    from skill.vocabulary import Vocabulary

    def some(status: Status, count: int, start: int, connected: bool = True) -> list[IndexedRobot]:
        state = Reported(status=status, zone="C", connected=connected)
        return [IndexedRobot(f"rover{start + n}", state) for n in range(min(count, NAMED_MAX))]

    counts = {"idle": SIZE - 30 - stuck - failed, "navigating": 20, "stuck": stuck, "error": failed}
    state = FleetState(
        total=SIZE + 5,  # five never reported
        counts={status: n for status, n in counts.items() if n},
        offline=offline,
        troubled={
            kind: robots
            for kind, robots in {
                "stuck": some("stuck", stuck, 100),
                "error": some("error", failed, 200),
                "offline": some("idle", offline, 300, connected=False),
            }.items()
            if robots
        },
    )
    vocabulary = Vocabulary(big_fleet)
    for said in (fleet_summary(vocabulary, state), problem_report(vocabulary, state)):
        assert len(said.split()) <= MAX_WORDS, said
    summary = fleet_summary(vocabulary, state)
    assert summary.startswith("Of 1,005 robots, ") and "5 have not reported" in summary
    if stuck:
        assert f"{stuck} {'is' if stuck == 1 else 'are'} stuck: rover 100 in zone C" in summary
    if offline:
        assert f"{offline} {'is' if offline == 1 else 'are'} offline" in summary


def test_robots_are_named_in_the_order_a_person_counts_them() -> None:
    from skill.fleet_status import spoken_order
    from skill.iot_fleet_index import IndexedRobot

    robots = [IndexedRobot(thing, Reported()) for thing in ("rover1000", "rover101", "rover99")]
    assert [robot.thing for robot in spoken_order(robots)] == ["rover99", "rover101", "rover1000"]


@pytest.fixture
def answering_plane(
    big_fleet: Fleet, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> Iterator[tuple[Callable[[dict[str, Any], Any], dict[str, Any]], Meter]]:
    """1,000 robots that answer a fleet command in their shadows as robots do, except
    rover5 and rover6 (refuse it) and rover7 to rover10 (never hear it); and the skill."""
    from skill.app import make_lambda_handler
    from skill.config import SkillConfig
    from vahr.protocol import LastCommand, decode_command

    store = ShadowStore()
    for thing in big_fleet.robot_things:
        _report(store, thing, Reported(status="idle", connected=True))
    store.commit()

    def robots_answer(topic: str, payload: bytes, _qos: int, _retain: bool) -> None:
        command = decode_command(payload)
        for number, thing in enumerate(big_fleet.robot_things, start=1):
            if 7 <= number <= 10:
                continue
            refused = number in (5, 6)
            last = LastCommand(
                id=command.id,
                action=command.action,
                result="rejected" if refused else "accepted",
                reason="its battery is low" if refused else None,
            )
            _report(store, thing, Reported(status="navigating", last_command=last, connected=True))
        store.commit()

    meter = Meter()
    dataplane = DataPlane(ShadowService(store, lambda _t, _p: None), robots_answer, meter)
    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "testing")
    monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "testing")
    fleet_file = write_fleet(big_fleet, tmp_path / "fleet.yaml")
    with DataPlaneServer(dataplane, 0) as server:
        config = SkillConfig(data_endpoint=server.url, fleet_file=str(fleet_file))
        yield make_lambda_handler(config), meter


def test_a_command_to_a_thousand_robots_is_confirmed_by_the_index(
    answering_plane: tuple[Callable[[dict[str, Any], Any], dict[str, Any]], Meter],
) -> None:
    skill, meter = answering_plane
    # When the person sends every robot to the loading zone
    said = speech(skill(load_event("alexa_navigate_fleet"), None))
    # Then the reply counts the 994 that confirmed and names the first of the six that did not
    assert said == (
        "994 of 1,000 robots confirmed; rover 5 refused: its battery is low; rover 6 refused: "
        "its battery is low; rover 7 had not answered yet; and 3 more had not confirmed yet."
    )
    # And not one shadow was read to find out
    assert "http.shadow.get" not in json.dumps(meter.snapshot())


def test_asking_which_robot_of_a_thousand_names_a_few_and_how_to_name_the_others(
    big_fleet: Fleet,
) -> None:
    from skill.vocabulary import Vocabulary

    choices = Vocabulary(big_fleet).robot_choices()
    assert choices == "rover 1, rover 2, rover 3, or another of the 1,000 robots by its name"
