"""The local announcer without a broker: what `GET /vahr/announcements` shows when the rate
limit holds announcements back, tells them later, and drops only past its bound."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING

from tests.conftest import load_event
from vahr.announce import settings_from
from vahr.local.announce_host import Announcer
from vahr.protocol import encode, topics

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.protocol.announcements import Announcement

T0 = datetime(2026, 11, 22, 10, 15, 3, tzinfo=UTC)


@dataclass
class Clock:
    now: datetime = T0

    def __call__(self) -> datetime:
        return self.now


def event(name: str, **changes: object) -> bytes:
    return encode({**load_event(name), **changes})


def test_held_announcements_are_told_later_and_counted_in_the_history(fleet: Fleet) -> None:
    # Given an announcer that may tell one thing a minute, and finished tasks worth telling
    clock = Clock()
    published: list[Announcement] = []
    announcer = Announcer(
        fleet,
        settings_from(
            {
                "max_per_window": 1,
                "reserve_for_urgent": 0,
                "max_held": 1,
                "kinds": ["stuck", "done"],
            }
        ),  # fmt: skip
        clock=clock,
        publish=published.append,
    )
    # When a robot gets stuck and two tasks finish at once
    announcer.on_event(topics.robot_events("placebot1"), event("robot_event_stuck"))
    announcer.on_event(topics.robot_events("placebot2"), event("robot_event_done"))
    announcer.on_event(
        topics.robot_events("placebot2"),
        event("robot_event_done", at="2026-11-22T10:19:00Z", command_id="c-46"),
    )
    # Then one is told now, one waits its turn, and the one past the bound is counted
    status, body = announcer.route({})
    assert status == 200
    assert [a["kind"] for a in body["announcements"]] == ["stuck"]
    assert (body["held"], body["withdrawn"], body["dropped"]) == (2, 0, 1)
    # And the one that waited is told when the window allows, on the topic and in the history
    clock.now += timedelta(seconds=60)
    [late] = announcer.tick()
    assert late.speech == "Placebot two has finished its task at zone C."
    assert [a.kind for a in published] == ["stuck", "done"]
    assert [a["kind"] for a in announcer.route({})[1]["announcements"]] == ["stuck", "done"]
