"""The announcement policy: what is worth telling, once per fault, within a rate limit,
most urgent first, on an injected clock."""

from __future__ import annotations

import json
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING

import msgspec
import pytest
from conftest import load_event

from vahr.announce import (
    AnnouncePolicy,
    Dispatched,
    PolicyState,
    Queued,
    settings_from,
    signals_from_event,
    signals_from_presence,
)
from vahr.announce.speech import Names
from vahr.protocol import ProtocolError, decode_event, decode_presence

if TYPE_CHECKING:
    from vahr.protocol import Fleet
    from vahr.protocol.announcements import Announcement

T0 = datetime(2026, 11, 22, 10, 15, 3, 120000, tzinfo=UTC)


@dataclass
class Clock:
    now: datetime = T0

    def __call__(self) -> datetime:
        return self.now

    def advance(self, seconds: float) -> None:
        self.now += timedelta(seconds=seconds)


def event(name: str, **changes: object) -> bytes:
    return json.dumps({**load_event(name), **changes}).encode()


def policy(fleet: Fleet, clock: Clock, **settings: object) -> AnnouncePolicy:
    return AnnouncePolicy(settings_from(settings), Names.of(fleet), clock)


def robot_event(p: AnnouncePolicy, name: str, **changes: object) -> list[Announcement]:
    return p.observe(signals_from_event(decode_event(event(name, **changes))))


def presence(p: AnnouncePolicy, thing: str, name: str) -> list[Announcement]:
    return p.observe(signals_from_presence(thing, decode_presence(event(name))))


def test_a_stuck_robot_is_told_once_by_name_and_where_it_was_going(fleet: Fleet) -> None:
    # Given a robot that gets stuck, then ends its task as failed because it was stuck
    p = policy(fleet, Clock())
    first = robot_event(p, "robot_event_stuck")
    second = robot_event(p, "robot_event_failed_stuck")
    # Then the person hears one announcement, naming the robot and its goal
    assert [a.speech for a in first] == [
        "Placebot one is stuck on its way to zone b and needs your help."
    ]
    assert second == []
    [told] = first
    assert (told.thing, told.kind, told.person, told.priority) == (
        "placebot1",
        "stuck",
        "everyone",
        3,
    )
    assert told.reason == "no progress towards B for 10 s"
    assert told.opened_at == T0 and told.time == T0


def test_the_same_fault_again_is_not_told_until_it_clears(fleet: Fleet) -> None:
    # Given a stuck robot whose stuck event arrives twice (a QoS 1 redelivery)
    clock = Clock()
    p = policy(fleet, clock)
    assert len(robot_event(p, "robot_event_stuck")) == 1
    assert robot_event(p, "robot_event_stuck") == []
    # When the person sends it a new command, and it gets stuck again later
    robot_event(p, "robot_event_accepted")
    clock.advance(30)
    again = robot_event(p, "robot_event_stuck", at=clock.now.isoformat())
    # Then the new fault is told
    assert [a.kind for a in again] == ["stuck"]


def test_a_failed_task_is_told_with_its_reason(fleet: Fleet) -> None:
    told = robot_event(policy(fleet, Clock()), "robot_event_failed")
    assert [a.speech for a in told] == [
        "Placebot two could not finish its task: goal to C aborted: the planner found no path."
    ]


def test_offline_is_told_when_presence_is_lost_and_clears_when_back(fleet: Fleet) -> None:
    p = policy(fleet, Clock())
    assert [a.speech for a in presence(p, "placebot2", "robot_presence_offline")] == [
        "Placebot two has gone offline."
    ]
    assert presence(p, "placebot2", "robot_presence_offline") == []
    presence(p, "placebot2", "robot_presence_online")
    assert p.open_faults() == []
    assert len(presence(p, "placebot2", "robot_presence_offline")) == 1


def test_an_offline_blip_shorter_than_the_grace_is_not_told(fleet: Fleet) -> None:
    # Given a grace of 5 s, and a robot that restarts within it
    clock = Clock()
    p = policy(fleet, clock, offline_grace_s=5)
    assert presence(p, "placebot1", "robot_presence_offline") == []
    clock.advance(2)
    presence(p, "placebot1", "robot_presence_online")
    clock.advance(10)
    # Then nothing is told; a robot that stays away is told once the grace has passed
    assert p.tick() == []
    presence(p, "placebot1", "robot_presence_offline")
    clock.advance(5)
    assert [a.kind for a in p.tick()] == ["offline"]


def test_the_rate_limit_holds_back_and_tells_later_most_urgent_first(fleet: Fleet) -> None:
    # Given at most one announcement a minute, and done worth telling
    clock = Clock()
    p = policy(fleet, clock, max_per_window=2, reserve_for_urgent=1, window_s=60,
               kinds=["stuck", "failed", "offline", "done"])  # fmt: skip
    # When a task finishes, another fails, and a robot goes offline, all at once
    burst = robot_event(p, "robot_event_done", at=T0.isoformat())
    burst += robot_event(p, "robot_event_failed", at=T0.isoformat())
    burst += presence(p, "placebot1", "robot_presence_offline")
    # Then the first two are told at once (done uses the share left for routine news)
    assert [a.kind for a in burst] == ["done", "failed"]
    # And offline, more urgent than anything, is told as soon as the window allows
    clock.advance(30)
    assert p.tick() == []
    clock.advance(31)
    assert [a.kind for a in p.tick()] == ["offline"]
    assert p.state.held >= 1


def test_routine_news_leaves_room_for_urgent_news(fleet: Fleet) -> None:
    # Given two a minute, one kept for urgent news, and done worth telling
    p = policy(fleet, Clock(), max_per_window=2, reserve_for_urgent=1,
               kinds=["stuck", "failed", "offline", "done"])  # fmt: skip
    told = robot_event(p, "robot_event_done")
    told += robot_event(p, "robot_event_done", thing="placebot1")
    # Then only one finished task is told, and a stuck robot still gets through at once
    assert [a.kind for a in told] == ["done"]
    assert [a.kind for a in robot_event(p, "robot_event_stuck")] == ["stuck"]


def test_a_held_fault_that_clears_before_its_turn_is_not_told(fleet: Fleet) -> None:
    clock = Clock()
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0)
    robot_event(p, "robot_event_failed")
    assert robot_event(p, "robot_event_stuck") == []  # held: the window is full
    robot_event(p, "robot_event_accepted")  # the person sent placebot1 a new command
    clock.advance(61)
    assert p.tick() == []


def test_the_rate_limit_is_per_person(fleet: Fleet) -> None:
    # Given each robot's announcements going to its own operator, one a minute each
    alice, bob = "amzn1.ask.account.ALICE", "amzn1.ask.account.BOB"
    p = policy(fleet, Clock(), max_per_window=1, reserve_for_urgent=0,
               audience={"placebot1": alice, "placebot2": bob})  # fmt: skip
    told = robot_event(p, "robot_event_stuck") + robot_event(p, "robot_event_failed")
    # Then both are told at once, each to its person
    assert [(a.thing, a.person) for a in told] == [("placebot1", alice), ("placebot2", bob)]


def test_done_is_off_by_default_and_stale_done_is_dropped(fleet: Fleet) -> None:
    clock = Clock()
    assert robot_event(policy(fleet, clock), "robot_event_done") == []
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0, done_max_age_s=30,
               kinds=["stuck", "done"])  # fmt: skip
    robot_event(p, "robot_event_stuck")
    robot_event(p, "robot_event_done")  # held behind the stuck robot
    clock.advance(61)
    assert p.tick() == []
    assert p.state.dropped == 1


def test_a_queued_task_waiting_too_long_is_told_once_until_dispatched(fleet: Fleet) -> None:
    # Given a queue (none exists yet) that says task q-1 for placebot2 was queued at T0
    clock = Clock()
    p = policy(fleet, clock, queue_wait_s=120)
    assert p.observe([Queued("q-1", T0, thing="placebot2")]) == []
    clock.advance(100)
    assert p.tick() == []
    clock.advance(80)
    # Then once it has waited longer than queue_wait_s, it is told, once
    [told] = p.tick()
    assert told.speech == "A task for placebot two has waited 3 minutes in the queue."
    assert (told.kind, told.thing, told.opened_at) == ("waiting", "placebot2", T0)
    assert p.tick() == []
    # And when it is dispatched it waits no more
    p.observe([Dispatched("q-1", clock.now)])
    assert p.state.queued == [] and p.open_faults() == []


def test_the_state_survives_a_round_trip_so_a_stateless_function_dedups(fleet: Fleet) -> None:
    # Given the state saved after the first stuck event (as the cloud's announcer does)
    first = policy(fleet, Clock())
    robot_event(first, "robot_event_stuck")
    saved = msgspec.json.encode(first.state)
    # When a new policy loads it and sees the redelivered event
    second = AnnouncePolicy(first.settings, first.names, Clock(),
                            msgspec.json.decode(saved, type=PolicyState))  # fmt: skip
    # Then nothing is told again
    assert robot_event(second, "robot_event_stuck") == []


def test_the_same_fault_keeps_the_same_id_so_a_retry_is_a_duplicate(fleet: Fleet) -> None:
    a = robot_event(policy(fleet, Clock()), "robot_event_stuck")
    b = robot_event(policy(fleet, Clock()), "robot_event_stuck")
    assert a[0].id == b[0].id
    assert a[0].id.startswith("vahr~stuck~")


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"max_per_window": 0}, "max_per_window: expected `int` >= 1"),
        ({"reserve_for_urgent": 4}, "reserve_for_urgent: 4 must be less than max_per_window"),
        ({"kinds": ["late"]}, "kinds.0: invalid enum value 'late'"),
        ({"windows": 3}, "windows: is not a known field"),
        ({"audience": {"placebot1": "bob"}}, "audience"),
    ],
)
def test_bad_settings_are_refused_naming_the_field(
    settings: dict[str, object], message: str
) -> None:
    with pytest.raises(ProtocolError, match=rf"^{message}"):
        settings_from(settings)
