"""Fleet dispatch in the skill: real ASK envelopes in, the words Alexa would speak out.

The skill's `TaskDesk` is a desk over the dispatch core itself (the real `Dispatcher` on a
SQLite store in a temporary directory) whose robots are states set by each test, so the
replies are checked against what the dispatcher really decided: which robot, which place
in line. The fleet is the made-up six-robot bakery of tests/fleets/.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import speech

from skill import builder as skill_builder
from skill.config import SkillConfig
from skill.task_desk import TaskRefused
from tests.conftest import load_event
from tests.support.fleets import SIX_ROBOTS
from vahr.dispatch import (
    Dispatcher,
    DispatchError,
    Order,
    RobotState,
    ServiceChange,
    Submission,
    Task,
    ZoneChange,
)
from vahr.domain import load_fleet
from vahr.local.task_store import SqliteTaskStore

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from vahr.protocol import Command

BAKERY = load_fleet(SIX_ROBOTS)


class Robots:
    """The dispatcher's candidates: every robot idle at its start, unless a test says."""

    def __init__(self) -> None:
        self.states = {
            robot.thing: RobotState(thing=robot.thing, status="idle", pose=robot.start)
            for robot in BAKERY.robots
        }

    def busy(self, *things: str) -> None:
        for thing in things:
            self.states[thing] = RobotState(thing=thing, status="stuck")

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        return [s for s in self.states.values() if s.available and zone in (None, s.zone)]

    def state(self, thing: str) -> RobotState | None:
        return self.states.get(thing)


class CoreDesk:
    """A `TaskDesk` that is the dispatch core in-process, refusing as the HTTP route does."""

    def __init__(self, dispatcher: Dispatcher) -> None:
        self.dispatcher = dispatcher
        self.out: set[str] = set()

    def submit(self, order: Order) -> Submission:
        try:
            return self.dispatcher.submit(order)
        except DispatchError as err:
            raise TaskRefused(400, str(err), err.code) from err

    def tasks(self) -> list[Task]:
        return self.dispatcher.tasks()

    def cancel(self, task_id: str) -> Task | None:
        return self.dispatcher.cancel(task_id)

    def closed_zones(self) -> list[str]:
        return self.dispatcher.closed_zones()

    def set_zone(self, zone: str, *, closed: bool) -> ZoneChange:
        try:
            return self.dispatcher.set_zone(zone, closed=closed)
        except DispatchError as err:
            raise TaskRefused(400, str(err), err.code) from err

    def out_of_service(self) -> list[str]:
        return sorted(self.out)

    def set_service(self, thing: str, *, in_service: bool) -> ServiceChange:
        changed = (thing in self.out) == in_service
        self.out.discard(thing) if in_service else self.out.add(thing)
        if not changed:
            return ServiceChange(thing=thing, in_service=in_service, changed=False)
        if in_service:
            return self.dispatcher.reinstated(thing)
        return self.dispatcher.withdrawn(thing)

    def charge(self, thing: str) -> Task:
        try:
            task = self.dispatcher.charge(thing, asked=True)
        except DispatchError as err:
            raise TaskRefused(400, str(err), err.code) from err
        assert task is not None
        return task


@pytest.fixture
def robots() -> Robots:
    return Robots()


@pytest.fixture
def sent() -> list[tuple[str, Command]]:
    return []


@pytest.fixture
def desk(tmp_path: Path, robots: Robots, sent: list[tuple[str, Command]]) -> Iterator[CoreDesk]:
    store = SqliteTaskStore.in_state_dir(tmp_path)
    dispatcher = Dispatcher(
        fleet=BAKERY,
        store=store,
        candidates=robots,
        publish=lambda thing, command: sent.append((thing, command)),
    )
    yield CoreDesk(dispatcher)
    store.close()


@pytest.fixture
def skill(
    aws: None, desk: CoreDesk, monkeypatch: pytest.MonkeyPatch
) -> Callable[[dict[str, Any]], dict[str, Any]]:
    monkeypatch.setattr(skill_builder, "task_desk", lambda config: desk)
    handler = skill_builder.make_lambda_handler(SkillConfig(fleet_file=str(SIX_ROBOTS)))
    return lambda event: handler(event, None)


def _slot(name: str, spoken: str | None, value_id: str | None) -> dict[str, Any]:
    slot: dict[str, Any] = {"name": name, "confirmationStatus": "NONE"}
    if spoken is None:
        return slot
    authority = f"amzn1.er-authority.echo-sdk.amzn1.ask.skill.test.{name.upper()}"
    resolution: dict[str, Any]
    if value_id is None:
        resolution = {"authority": authority, "status": {"code": "ER_SUCCESS_NO_MATCH"}}
    else:
        resolution = {
            "authority": authority,
            "status": {"code": "ER_SUCCESS_MATCH"},
            "values": [{"value": {"name": spoken, "id": value_id}}],
        }
    slot.update(
        value=spoken,
        source="USER",
        resolutions={"resolutionsPerAuthority": [resolution]},
    )
    return slot


def intent(name: str, **slots: tuple[str | None, str | None]) -> dict[str, Any]:
    """A real-shaped IntentRequest for `name`, each slot (spoken words, resolved id)."""
    event = copy.deepcopy(load_event("alexa_navigate"))
    event["request"]["intent"] = {
        "name": name,
        "confirmationStatus": "NONE",
        "slots": {slot: _slot(slot, *value) for slot, value in slots.items()},
    }
    return event


def said(skill: Callable[[dict[str, Any]], dict[str, Any]], event: dict[str, Any]) -> str:
    return speech(skill(event))


def test_a_delivery_naming_no_robot_goes_to_the_robot_nearest_the_mill(
    skill: Callable[[dict[str, Any]], dict[str, Any]], sent: list[tuple[str, Command]]
) -> None:
    event = intent("DeliverIntent", robot=(None, None), zone=("the oven", "OVEN"))
    # osprey starts at (2, 6), 2.2 m from the mill at (4, 7): the shortest way there and on.
    assert said(skill, event) == "Osprey is on its way to pick up a package for the oven."
    [(thing, command)] = sent
    assert (thing, command.action, command.params.zone) == ("osprey", "deliver", "OVEN")  # type: ignore[union-attr]


def test_a_delivery_naming_a_robot_is_unchanged(
    skill: Callable[[dict[str, Any]], dict[str, Any]], sent: list[tuple[str, Command]]
) -> None:
    event = intent("DeliverIntent", robot=("kestrel", "kestrel"), zone=("the oven", "OVEN"))
    skill(event)
    assert sent == []  # published by the skill itself, not through the dispatcher


def test_two_robots_are_named_and_a_third_is_queued_when_only_two_are_free(
    skill: Callable[[dict[str, Any]], dict[str, Any]], robots: Robots
) -> None:
    robots.busy("kestrel", "heron", "osprey", "plover")
    event = intent("FleetNavigateIntent", zone=("the shop", "SHOP"), count=("three", "3"))
    assert said(skill, event) == (
        "Curlew and dunlin are on their way to the shop. "
        "No other robot is free, so one more waits, first in line."
    )


def test_with_every_robot_busy_the_delivery_is_queued_and_its_place_said(
    skill: Callable[[dict[str, Any]], dict[str, Any]], robots: Robots
) -> None:
    robots.busy(*BAKERY.robot_things)
    first = intent("DeliverIntent", robot=(None, None), zone=("the pantry", "PANTRY"))
    second = intent("DeliverIntent", robot=(None, None), zone=("the oven", "OVEN"))
    assert said(skill, first) == "All robots are busy; the delivery to the pantry is first in line."
    assert said(skill, second) == "All robots are busy; the delivery to the oven is second in line."
    queue = said(skill, intent("TaskQueueIntent"))
    assert queue == (
        "Two tasks are queued: first, the delivery to the pantry; second, the delivery to the oven."
    )


def test_cancelling_the_delivery_to_a_zone_takes_it_out_of_line(
    skill: Callable[[dict[str, Any]], dict[str, Any]], robots: Robots, desk: CoreDesk
) -> None:
    robots.busy(*BAKERY.robot_things)
    skill(intent("DeliverIntent", robot=(None, None), zone=("the pantry", "PANTRY")))
    skill(intent("DeliverIntent", robot=(None, None), zone=("the oven", "OVEN")))
    cancel = intent("CancelTaskIntent", zone=("the pantry", "PANTRY"))
    assert said(skill, cancel) == "I cancelled the delivery to the pantry, which was first in line."
    assert [task.zone for task in desk.tasks()] == ["OVEN"]
    assert said(skill, cancel) == "There is no task to the pantry to cancel."


def test_cancelling_a_task_a_robot_holds_stops_that_robot(
    skill: Callable[[dict[str, Any]], dict[str, Any]], sent: list[tuple[str, Command]]
) -> None:
    skill(intent("FleetNavigateIntent", zone=("the shop", "SHOP")))
    thing = sent[-1][0]
    assert said(skill, intent("CancelTaskIntent", zone=("the shop", "SHOP"))) == (
        f"I cancelled the trip to the shop and stopped {thing}."
    )
    assert sent[-1] == (thing, sent[-1][1]) and sent[-1][1].action == "stop"


def test_cancelling_with_two_robots_heading_there_cancels_both_and_says_so(
    skill: Callable[[dict[str, Any]], dict[str, Any]],
    sent: list[tuple[str, Command]],
    desk: CoreDesk,
) -> None:
    # Given two robots sent to the shop
    skill(intent("FleetNavigateIntent", zone=("the shop", "SHOP"), count=("two", "2")))
    going = [task.thing for task in desk.tasks()]
    assert len(going) == 2
    # When the person cancels "the delivery to the shop"
    spoken = said(skill, intent("CancelTaskIntent", zone=("the shop", "SHOP")))
    # Then no task to the shop is left, both robots were stopped, and the answer says so
    assert desk.tasks() == []
    assert sorted(thing for thing, command in sent if command.action == "stop") == sorted(going)
    assert spoken == f"I cancelled the two tasks to the shop and stopped {going[0]} and {going[1]}."


def test_a_group_sends_each_member_and_says_which_are_busy(
    skill: Callable[[dict[str, Any]], dict[str, Any]], robots: Robots
) -> None:
    robots.busy("curlew")
    event = intent("FleetNavigateIntent", zone=("the oven", "OVEN"), group=("the waders", "waders"))
    assert said(skill, event) == (
        "Plover and dunlin are on their way to the oven. Curlew is busy and will go when free."
    )


def test_an_unknown_group_is_said_with_the_groups_there_are(
    skill: Callable[[dict[str, Any]], dict[str, Any]], sent: list[tuple[str, Command]]
) -> None:
    event = intent("FleetNavigateIntent", zone=("the oven", "OVEN"), group=("the swimmers", None))
    assert (
        said(skill, event) == "I don't know a group called the swimmers; the groups are the waders."
    )
    assert sent == []


def test_more_robots_than_the_fleet_has_is_said_and_nothing_moves(
    skill: Callable[[dict[str, Any]], dict[str, Any]], sent: list[tuple[str, Command]]
) -> None:
    event = intent("FleetNavigateIntent", zone=("the oven", "OVEN"), count=("nine", "9"))
    assert said(skill, event) == "The fleet has 6 robots, so I cannot send 9."
    assert sent == []


def test_an_unknown_zone_is_asked_about_with_the_zones_there_are(
    skill: Callable[[dict[str, Any]], dict[str, Any]], sent: list[tuple[str, Command]]
) -> None:
    response = skill(intent("FleetNavigateIntent", zone=("the moon", None)))
    assert speech(response).startswith("I don't know a zone called the moon. To which zone: ")
    assert "the shop" in speech(response)
    assert response["response"]["directives"][0]["type"] == "Dialog.ElicitSlot"
    assert sent == []


def test_the_robots_in_a_zone_go_and_none_there_is_said(
    skill: Callable[[dict[str, Any]], dict[str, Any]], robots: Robots
) -> None:
    for thing in ("heron", "plover"):
        robots.states[thing] = RobotState(thing=thing, status="idle", zone="SHOP")
    event = intent("ZoneRobotsIntent", origin=("the shop", "SHOP"), zone=("the mill", "LOADING"))
    assert said(skill, event) == "Heron and plover are on their way to the mill."
    empty = intent(
        "ZoneRobotsIntent", origin=("the pantry", "PANTRY"), zone=("the mill", "LOADING")
    )
    assert said(skill, empty) == "No free robot is in the pantry, so I sent none."


def test_a_refusal_is_read_by_its_code_not_its_words(
    skill: Callable[[dict[str, Any]], dict[str, Any]],
    robots: Robots,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Given a dispatcher whose refusal says "none free" in other words than today's
    def refuse(order: Order) -> Submission:
        raise TaskRefused(400, "alle Roboter sind unterwegs", "none_free")

    monkeypatch.setattr(CoreDesk, "submit", lambda self, order: refuse(order))
    event = intent("ZoneRobotsIntent", origin=("the shop", "SHOP"), zone=("the mill", "LOADING"))
    # Then the skill says what its code means
    assert said(skill, event) == "No free robot is in the shop, so I sent none."


def test_every_idle_robot_goes_and_busy_ones_stay(
    skill: Callable[[dict[str, Any]], dict[str, Any]],
    robots: Robots,
    sent: list[tuple[str, Command]],
) -> None:
    robots.states["heron"] = RobotState(thing="heron", status="navigating")
    event = intent("IdleRobotsIntent", zone=("the shop", "SHOP"))
    assert said(skill, event) == (
        "Curlew, dunlin, kestrel, osprey and plover are on their way to the shop."
    )
    assert "heron" not in {thing for thing, _ in sent}


def test_without_a_dispatcher_the_skill_says_so(aws: None, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(skill_builder, "task_desk", lambda config: None)
    handler = skill_builder.make_lambda_handler(SkillConfig(fleet_file=str(SIX_ROBOTS)))
    response = handler(intent("FleetNavigateIntent", zone=("the shop", "SHOP")), None)
    assert "fleet dispatcher, which is not running here" in speech(response)


def test_a_zone_closed_by_voice_takes_no_robot_and_its_queue_waits_until_it_opens(
    skill: Callable[[dict[str, Any]], dict[str, Any]],
    robots: Robots,
    sent: list[tuple[str, Command]],
    desk: CoreDesk,
) -> None:
    # Given every robot busy and a delivery to the oven queued
    robots.busy(*BAKERY.robot_things)
    said(skill, intent("DeliverIntent", robot=(None, None), zone=("the oven", "OVEN")))
    # When the oven is closed
    close = intent("CloseZoneIntent", zone=("the oven", "OVEN"))
    assert said(skill, close) == (
        "The oven is closed. No robot will be sent there until it opens. "
        "One queued task to it waits until it opens."
    )
    assert desk.closed_zones() == ["OVEN"]
    # Then the queue says what waits for it, and nothing goes there, by name or not
    assert said(skill, intent("TaskQueueIntent")) == (
        "One task is queued: first, the delivery to the oven, waiting until the oven opens."
    )
    by_name = intent("NavigateIntent", robot=("kestrel", "kestrel"), zone=("the oven", "OVEN"))
    assert said(skill, by_name) == "The oven is closed, so I sent no robot there."
    fleet = intent("FleetNavigateIntent", zone=("the oven", "OVEN"))
    assert said(skill, fleet) == "The oven is closed, so I sent no robot there."
    assert sent == []
    # Closing it again says it already was
    assert said(skill, close) == (
        "The oven was already closed. One queued task to it waits until it opens."
    )
    # When it is opened (every robot still busy), it says so; opening twice says it was open
    opening = intent("OpenZoneIntent", zone=("the oven", "OVEN"))
    assert said(skill, opening) == "The oven is open again."
    assert said(skill, opening) == "The oven was not closed."
    assert desk.closed_zones() == []


def test_closing_a_zone_is_said_in_german(
    skill: Callable[[dict[str, Any]], dict[str, Any]], desk: CoreDesk
) -> None:
    event = intent("CloseZoneIntent", zone=("die backstube", "OVEN"))
    event["request"]["locale"] = "de-DE"
    speech_said = said(skill, event)
    assert speech_said.endswith(
        "ist gesperrt. Bis sie wieder offen ist, schicke ich keinen Roboter dorthin."
    )
    assert desk.closed_zones() == ["OVEN"]


def test_a_robot_out_of_service_is_not_sent_by_name_and_back_in_service_it_is(
    skill: Callable[[dict[str, Any]], dict[str, Any]],
    sent: list[tuple[str, Command]],
    desk: CoreDesk,
) -> None:
    # When the heron is taken out of service by voice
    out = intent("OutOfServiceIntent", robot=("heron", "heron"))
    assert said(skill, out) == "Heron is out of service now and gets no tasks."
    assert desk.out_of_service() == ["heron"]
    assert said(skill, out) == "Heron was already out of service."
    # Then a command naming it is not sent, and says why; a stop still is
    by_name = intent("NavigateIntent", robot=("heron", "heron"), zone=("the oven", "OVEN"))
    assert said(skill, by_name) == "Heron is out of service, so I sent nothing."
    charge = intent("ChargeIntent", robot=("heron", "heron"))
    assert said(skill, charge) == "Heron is out of service, so I sent nothing."
    assert sent == []
    # Back in service, it takes commands again
    back = intent("BackInServiceIntent", robot=("heron", "heron"))
    assert said(skill, back) == "Heron is back in service."
    assert desk.out_of_service() == []
    assert said(skill, by_name) != "Heron is out of service, so I sent nothing."


def test_taking_a_group_out_of_service_names_its_members_in_german(
    skill: Callable[[dict[str, Any]], dict[str, Any]], desk: CoreDesk
) -> None:
    event = intent("OutOfServiceIntent", group=("die watvögel", "waders"))
    event["request"]["locale"] = "de-DE"
    spoken = said(skill, event)
    assert spoken.endswith("sind jetzt außer Betrieb und bekommen keine Aufträge."), spoken
    assert desk.out_of_service() == ["curlew", "dunlin", "plover"]


def test_with_confirmation_on_a_zone_is_closed_only_after_its_askers_yes(
    aws: None, desk: CoreDesk, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given a skill that confirms fleet-wide commands first
    monkeypatch.setattr(skill_builder, "task_desk", lambda config: desk)
    handler = skill_builder.make_lambda_handler(
        SkillConfig(fleet_file=str(SIX_ROBOTS), confirm=True)
    )
    close = intent("CloseZoneIntent", zone=("the oven", "OVEN"))
    # When someone asks to close the oven, it is said back and nothing is closed yet
    asked = handler(close, None)
    assert speech(asked) == "Close the oven, so that no robot goes there, is that right?"
    assert asked["response"]["directives"][0]["type"] == "Dialog.ConfirmIntent"
    assert desk.closed_zones() == []
    # Then their yes closes it
    yes = copy.deepcopy(close)
    yes["session"]["new"] = False
    yes["session"]["attributes"] = asked.get("sessionAttributes") or {}
    yes["request"]["dialogState"] = "IN_PROGRESS"
    yes["request"]["intent"]["confirmationStatus"] = "CONFIRMED"
    assert speech(handler(yes, None)).startswith("The oven is closed.")
    assert desk.closed_zones() == ["OVEN"]
