"""The announcement policy: what is worth telling, once per fault, within a rate limit,
most urgent first, on an injected clock."""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING

import msgspec
import pytest

from tests.conftest import load_event
from vahr.announce import (
    AnnouncePolicy,
    Dispatched,
    PolicyState,
    Queued,
    TaskCancelled,
    settings_from,
    signals_from_event,
    signals_from_presence,
)
from vahr.announce.speech import Names
from vahr.protocol import ProtocolError, decode_event, decode_presence
from vahr.protocol.announcements import decode_announcement

if TYPE_CHECKING:
    from vahr.domain import Fleet
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
        "Placebot one is stuck on its way to zone B and needs your help."
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


def test_a_held_fault_that_clears_before_its_turn_is_not_told_and_the_log_says_so(
    fleet: Fleet, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="vahr.announce")
    clock = Clock()
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0)
    robot_event(p, "robot_event_failed")
    assert robot_event(p, "robot_event_stuck") == []  # held: the window is full
    robot_event(p, "robot_event_accepted")  # the person sent placebot1 a new command
    clock.advance(61)
    assert p.tick() == []
    # Then it is counted as withdrawn, not dropped, and the log tells why it was not told
    assert (p.state.held, p.state.withdrawn, p.state.dropped) == (1, 1, 0)
    assert (
        "not announcing placebot1 stuck: it cleared before it was told (held back by the rate limit)"
        in caplog.text
    )


def test_what_the_rate_limit_holds_back_is_told_however_long_it_waited(fleet: Fleet) -> None:
    # Given one announcement a minute, taken by a stuck robot, and a finished task behind it
    clock = Clock()
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0, kinds=["stuck", "done"])
    assert [a.kind for a in robot_event(p, "robot_event_stuck")] == ["stuck"]
    assert robot_event(p, "robot_event_done") == []
    # When nothing else happens for ten minutes and the announcer only ticks
    told: list[Announcement] = []
    for _ in range(40):
        clock.advance(15)
        told += p.tick()
    # Then the finished task was told once, as soon as the window allowed, and nothing was
    # dropped; holding it back was counted once, not once a tick
    assert [(a.kind, a.time - T0) for a in told] == [("done", timedelta(seconds=60))]
    assert (p.state.held, p.state.dropped) == (1, 0)
    assert p.state.finished == []


def test_a_held_finished_task_is_told_at_the_first_chance_even_if_old(fleet: Fleet) -> None:
    clock = Clock()
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0, kinds=["stuck", "done"])
    robot_event(p, "robot_event_stuck")
    robot_event(p, "robot_event_done", at=T0.isoformat())
    clock.advance(59)
    assert p.tick() == []
    # When the announcer next looks five minutes after it finished (no tick in between)
    clock.advance(241)
    # Then it is still told: an old announcement is late, not lost
    [late] = p.tick()
    assert late.speech == "Placebot two has finished its task at zone C."
    assert late.time - late.opened_at == timedelta(minutes=5)


def test_held_announcements_are_told_most_urgent_first_then_oldest_first(fleet: Fleet) -> None:
    # Given a full window and, held behind it, a finished task, a failed task and a stuck robot
    clock = Clock()
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0,
               kinds=["stuck", "failed", "offline", "done"])  # fmt: skip
    presence(p, "placebot1", "robot_presence_offline")
    robot_event(p, "robot_event_done", at=(T0 + timedelta(seconds=1)).isoformat())
    robot_event(p, "robot_event_failed", at=(T0 + timedelta(seconds=2)).isoformat())
    robot_event(p, "robot_event_stuck", at=(T0 + timedelta(seconds=3)).isoformat())
    # Then one a minute is told: stuck, failed, then done
    told = []
    for _ in range(3):
        clock.advance(60)
        told += [a.kind for a in p.tick()]
    assert told == ["stuck", "failed", "done"]


def test_past_max_held_the_last_in_line_is_dropped_logged_and_counted(
    fleet: Fleet, caplog: pytest.LogCaptureFixture
) -> None:
    # Given room for two waiting announcements, and a full window
    clock = Clock()
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0, max_held=2,
               kinds=["stuck", "failed", "done"])  # fmt: skip
    robot_event(p, "robot_event_stuck")
    # When three finished tasks wait behind it
    for second in (1, 2, 3):
        robot_event(p, "robot_event_done", at=(T0 + timedelta(seconds=second)).isoformat())
    # Then the newest, last in line, is dropped with a warning naming it, and counted
    assert p.state.dropped == 1
    [warning] = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert warning == (
        "dropped the announcement of placebot2 done (opened at 2026-11-22T10:15:06.120000+00:00): "
        "more than 2 were waiting"
    )
    # And the two kept are told, oldest first, as the window allows
    clock.advance(60)
    [first] = p.tick()
    clock.advance(60)
    [second] = p.tick()
    assert [first.opened_at, second.opened_at] == [
        T0 + timedelta(seconds=1),
        T0 + timedelta(seconds=2),
    ]


def test_a_dropped_fault_stays_open_so_its_repeat_is_not_told_until_it_clears(
    fleet: Fleet,
) -> None:
    # Given room for one waiting announcement behind a full window
    clock = Clock()
    p = policy(fleet, clock, max_per_window=1, reserve_for_urgent=0, max_held=1)
    presence(p, "placebot1", "robot_presence_offline")  # told
    robot_event(p, "robot_event_stuck")  # held
    robot_event(p, "robot_event_failed")  # held, then dropped: failed is less urgent
    assert p.state.dropped == 1
    # When placebot2's failure arrives again (a redelivery) it is the same fault
    clock.advance(60)
    assert [a.kind for a in p.tick()] == ["stuck"]
    clock.advance(60)
    assert robot_event(p, "robot_event_failed") == []
    # And once placebot2 takes a new command and fails again, that is told
    robot_event(p, "robot_event_accepted", thing="placebot2")
    again = robot_event(p, "robot_event_failed", at=clock.now.isoformat())
    assert [a.kind for a in again] == ["failed"]


def test_the_rate_limit_is_per_person(fleet: Fleet) -> None:
    # Given each robot's announcements going to its own operator, one a minute each
    alice, bob = "amzn1.ask.account.ALICE", "amzn1.ask.account.BOB"
    p = policy(fleet, Clock(), max_per_window=1, reserve_for_urgent=0,
               audience={"placebot1": alice, "placebot2": bob})  # fmt: skip
    told = robot_event(p, "robot_event_stuck") + robot_event(p, "robot_event_failed")
    # Then both are told at once, each to its person
    assert [(a.thing, a.person) for a in told] == [("placebot1", alice), ("placebot2", bob)]


def test_done_is_off_by_default(fleet: Fleet) -> None:
    p = policy(fleet, Clock())
    assert robot_event(p, "robot_event_done") == []
    assert p.state.finished == []


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
        ({"max_held": 0}, "max_held: expected `int` >= 1"),
        ({"audience": {"placebot1": "bob"}}, "audience"),
    ],
)
def test_bad_settings_are_refused_naming_the_field(
    settings: dict[str, object], message: str
) -> None:
    with pytest.raises(ProtocolError, match=rf"^{message}"):
        settings_from(settings)


def test_a_task_given_up_for_a_command_by_name_is_told_once_with_its_place(fleet: Fleet) -> None:
    clock = Clock()
    p = policy(fleet, clock)
    # When the fleet gives up placebot2's delivery to zone C (it was sent elsewhere by name)
    [told] = p.observe([TaskCancelled("t-1", "placebot2", "deliver", "C", T0)])
    # Then it is told, by the robot's and the zone's names, and only once
    assert (told.kind, told.thing) == ("cancelled", "placebot2")
    assert told.speech == (
        "Placebot two was given another command, so its delivery to zone C is cancelled."
    )
    clock.advance(120)
    assert p.tick() == []


def test_a_robot_sent_to_charge_by_itself_is_told_once_in_both_languages(fleet: Fleet) -> None:
    from vahr.announce import LowBattery

    clock = Clock()
    p = policy(fleet, clock)
    [told] = p.observe([LowBattery("placebot1", T0, zone="A")])
    assert (told.kind, told.thing) == ("battery_low", "placebot1")
    assert told.speech == "Placebot one is low on battery and is going to charge."
    # Its id is one Alexa's Proactive Events API takes (letters, digits and '~').
    assert told.id.startswith("vahr~batterylow~")
    decode_announcement(msgspec.json.encode(told))
    clock.advance(120)
    assert p.tick() == []
    german = AnnouncePolicy(settings_from({}), Names.of(fleet, "de-DE"), Clock())
    [gesagt] = german.observe([LowBattery("placebot1", T0)])
    assert gesagt.speech == "Placebot eins hat wenig Akku und fährt zum Laden."


def test_announcements_are_said_in_the_stacks_language() -> None:
    from tests.support.fleets import HOSPITAL
    from vahr.domain import load_fleet

    p = AnnouncePolicy(settings_from({}), Names.of(load_fleet(HOSPITAL), "de-DE"), Clock())
    [told] = p.observe([TaskCancelled("t-1", "iris", "deliver", "WARD_THREE", T0)])
    assert told.speech == (
        "Iris hat einen anderen Befehl bekommen, also ist seine Lieferung nach Station Drei "
        "storniert."
    )
    [failed] = robot_event(
        p, "robot_event_failed", thing="iris", zone="PHARMACY",
        reason="goal to PHARMACY aborted: an injected fault",
    )  # fmt: skip
    assert failed.speech == (
        "Iris konnte seinen Auftrag nicht beenden: goal to Apotheke aborted: an injected fault."
    )


def test_every_english_announcement_word_has_a_german_one_with_its_placeholders() -> None:
    import string

    from vahr.announce.speech import WORDS
    from vahr.domain.locale import locale_file, read_yaml

    german = read_yaml(locale_file("de-DE", "announcements.yaml"), dict[str, str])
    assert set(german) == set(WORDS)

    def fields(text: str) -> set[str]:
        return {name for _, name, _, _ in string.Formatter().parse(text) if name}

    for name, english in WORDS.items():
        assert fields(german[name]) == fields(english), name
