"""Closing and opening a zone at the station's panel: a change to the whole fleet's
service, so a supervisor's; every change asked for, done, refused or failed, is in the
audit trail with the person who asked."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.station_stand_ins import RecordingAssistant, Wire
from vahr.domain.people import Person
from vahr.station.app import StationApp
from vahr.station.controls import Controls
from vahr.station.desk import Desk
from vahr.station.errors import RequestError
from vahr.station.feed import Feed

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.protocol.audit import AuditEntry

SUPERVISOR = Person(id="amzn1.ask.person.sam", role="supervisor", name="Sam")
OPERATOR = Person(id="amzn1.ask.person.olu", role="operator", name="Olu")


class Dispatcher:
    """The dispatcher's zone switch as the station calls it (`ZoneSwitch.set`)."""

    def __init__(self, *, given: list[dict[str, Any]] | None = None, fails: bool = False):
        self.given = given or []
        self.fails = fails
        self.calls: list[tuple[str, bool]] = []

    def set(self, zone: str, *, closed: bool) -> dict[str, object]:
        self.calls.append((zone, closed))
        if self.fails:
            raise RequestError(503, "the dispatcher cannot be reached: connection refused")
        return {"zone": zone, "closed": closed, "changed": True, "waiting": [], "given": self.given}


def station(fleet: Fleet, zones: Dispatcher, trail: list[AuditEntry]) -> StationApp:
    wire = Wire()
    feed = Feed(fleet)
    desk = Desk(feed, wire.publish)
    return StationApp(
        feed=feed,
        controls=Controls(fleet, desk, wire.publish, trail.append),
        desk=desk,
        assistant=RecordingAssistant(),
        push_to_talk=None,
        synthesize=None,
        zones=zones,  # type: ignore[arg-type]
    )


def switch(app: StationApp, body: object, who: Person) -> tuple[int, dict[str, Any]]:
    reply = app.handle_json("POST", "/api/zone", json.dumps(body).encode(), who)
    return reply.status, json.loads(reply.body)


def test_a_supervisor_closes_a_zone_and_the_trail_says_who(fleet: Fleet) -> None:
    trail: list[AuditEntry] = []
    zones = Dispatcher()
    status, change = switch(station(fleet, zones, trail), {"zone": "B", "closed": True}, SUPERVISOR)
    assert (status, change["closed"], zones.calls) == (200, True, [("B", True)])
    (record,) = trail
    assert (record.who, record.name, record.role, record.channel) == (
        SUPERVISOR.id,
        "Sam",
        "supervisor",
        "station-panel",
    )
    assert (record.words, record.slots, record.outcome) == ("close zone B", {"zone": "B"}, "sent")


def test_an_operator_may_not_close_a_zone_and_nothing_changes(fleet: Fleet) -> None:
    trail: list[AuditEntry] = []
    zones = Dispatcher()
    status, body = switch(station(fleet, zones, trail), {"zone": "B", "closed": True}, OPERATOR)
    assert status == 403
    assert body["error"].startswith("Olu is an operator, who may send and stop robots")
    assert zones.calls == []
    (record,) = trail
    assert (record.outcome, record.who, record.reason) == ("refused", OPERATOR.id, body["error"])


def test_opening_a_zone_records_the_waiting_tasks_it_gave_to_robots(fleet: Fleet) -> None:
    trail: list[AuditEntry] = []
    zones = Dispatcher(given=[{"id": "task-1", "thing": "placebot2", "zone": "B"}])
    status, _ = switch(station(fleet, zones, trail), {"zone": "B", "closed": False}, SUPERVISOR)
    assert status == 200
    (record,) = trail
    assert (record.words, record.robots, record.commands) == (
        "open zone B",
        ["placebot2"],
        ["task-1"],
    )


def test_a_dispatcher_that_cannot_be_reached_is_one_line_and_recorded_as_failed(
    fleet: Fleet,
) -> None:
    trail: list[AuditEntry] = []
    app = station(fleet, Dispatcher(fails=True), trail)
    status, body = switch(app, {"zone": "B", "closed": True}, SUPERVISOR)
    assert (status, body) == (
        503,
        {"error": "the dispatcher cannot be reached: connection refused"},
    )
    (record,) = trail
    assert (record.outcome, record.reason) == ("failed", body["error"])


@pytest.mark.parametrize(
    ("body", "error"),
    [
        ({"zone": "Q", "closed": True}, "zone: 'Q' is not a zone; zones are LOADING, A, B, C, D"),
        ({"zone": "B"}, "closed"),
    ],
)
def test_a_bad_zone_change_is_one_line_and_changes_nothing(
    fleet: Fleet, body: dict[str, Any], error: str
) -> None:
    trail: list[AuditEntry] = []
    zones = Dispatcher()
    status, answer = switch(station(fleet, zones, trail), body, SUPERVISOR)
    assert status == 400 and error in answer["error"]
    assert zones.calls == [] and trail == []
