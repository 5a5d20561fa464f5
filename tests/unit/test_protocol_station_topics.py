"""The messages of the station's topics and its pages: validation in one place, the page's
clock mapped, the page messages told apart by their type."""

from __future__ import annotations

import json
import typing
from datetime import UTC, datetime, timedelta

import msgspec
import pytest

from tests.conftest import load_event
from vahr.protocol import EventKind, ProtocolError
from vahr.protocol.announcements import decode_announcement
from vahr.protocol.station_topics import (
    ExperimentStatus,
    Interaction,
    decode_experiment_status,
    decode_station_input,
    decode_turn,
    on_clock,
    turn_from_message,
)
from vahr.station.page_messages import (
    DRIVE_ENDS,
    EXCHANGE_EVENTS,
    AckMessage,
    AlertAcknowledgedMessage,
    AnnouncementMessage,
    EventMessage,
    PageMessage,
    encode_page_message,
)

NOW = datetime(2026, 11, 23, 10, 0, 0, tzinfo=UTC)


def test_an_interaction_round_trips() -> None:
    body = {"kind": "interaction", "session": "P01-keyboard-trial1", "id": "a1-3",
            "phase": "ended", "channel": "voice", "at": "2026-11-23T10:00:00Z",
            "sent": "2026-11-23T10:00:02.5Z", "text": "what is the weather", "asks": True,
            "speech": "It is sunny."}  # fmt: skip
    message = decode_station_input(json.dumps(body).encode())
    assert isinstance(message, Interaction) and message.asks and message.counts


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"kind": "gossip"}, "kind"),
        (
            {
                "kind": "puzzle",
                "session": "S",
                "count": 99,
                "at": "2026-11-23T10:00:00Z",
                "sent": "2026-11-23T10:00:00Z",
            },
            "count",
        ),
        (
            {
                "kind": "interaction",
                "session": "S",
                "id": "i",
                "phase": "started",
                "channel": "click",
                "at": "2026-11-23T10:00:00",
                "sent": "2026-11-23T10:00:00Z",
            },
            "at",
        ),
    ],
)
def test_bad_input_names_the_field(body: dict[str, object], field: str) -> None:
    with pytest.raises(ProtocolError) as raised:
        decode_station_input(json.dumps(body).encode())
    assert raised.value.field == field


def test_input_over_8_kb_is_refused() -> None:
    with pytest.raises(ProtocolError, match="payload"):
        decode_station_input(b"{" + b" " * 9000 + b"}")


def test_a_turn_and_a_status_decode() -> None:
    turn = decode_turn(b'{"utterance": "hi", "speech": "Hello.", "origin": "station"}')
    assert turn.origin == "station" and turn.commands == []
    with pytest.raises(ProtocolError):
        decode_turn(b'{"utterance": "hi", "speech": "Hello.", "origin": "Not An Origin"}')
    status = decode_experiment_status(
        b'{"session": "P01-vahr-trial1", "participant": "P01", "method": "vahr", "trial": 1}'
    )
    assert status == ExperimentStatus(
        session="P01-vahr-trial1", participant="P01", method="vahr", trial=1
    )


def test_the_pages_clock_is_moved_onto_the_receivers() -> None:
    # A tablet whose clock is five minutes fast: the press lasted 2 s before it was sent
    fast = NOW + timedelta(minutes=5)
    at = on_clock(fast, fast + timedelta(seconds=2), received=NOW)
    assert at == NOW - timedelta(seconds=2)
    # A sent time before the event (a clock stepping back) is no lead at all
    assert on_clock(NOW, NOW - timedelta(seconds=1), received=NOW) == NOW


def test_a_drive_ends_only_on_events_that_end_it() -> None:
    # Every drive ends with one of these; the rest are events a robot may send mid-drive
    assert {"arrived", "stopped", "stuck", "failed", "cancelled"} <= DRIVE_ENDS
    assert not {"rejected", "done", "accepted", "progress"} & DRIVE_ENDS
    assert (DRIVE_ENDS | EXCHANGE_EVENTS) <= set(typing.get_args(EventKind))


def test_page_messages_are_told_apart_by_their_type() -> None:
    decoder = msgspec.json.Decoder(PageMessage)
    ack = decoder.decode(b'{"type": "ack", "id": "c1", "thing": "placebot1", '
                         b'"event": "accepted", "latency_ms": 12.0}')  # fmt: skip
    assert ack == AckMessage(id="c1", thing="placebot1", event="accepted", latency_ms=12.0)
    message = EventMessage(event="said", thing="placebot1", at=NOW, text="hi", last_seen=5.0)
    body = json.loads(encode_page_message(message))
    # An event is sent as the robot sent it, with its type and when it was last seen
    assert body == {"type": "event", "event": "said", "thing": "placebot1",
                    "at": "2026-11-23T10:00:00Z", "text": "hi", "last_seen": 5.0}  # fmt: skip


def test_an_announcement_reaches_the_page_as_said_with_its_type_and_robots() -> None:
    announced = load_event("announcement_stuck")
    announcement = decode_announcement(json.dumps(announced).encode())
    message = AnnouncementMessage(**msgspec.structs.asdict(announcement), robots=["placebot1"])
    # The page gets every field the announcer sent, as it sent it, with its type and robots
    body = json.loads(encode_page_message(message))
    assert body == {"type": "announcement", **announced, "robots": ["placebot1"]}
    decoder = msgspec.json.Decoder(PageMessage)
    assert decoder.decode(encode_page_message(message)) == message
    acknowledged = decoder.decode(b'{"type": "alert_acknowledged", "ids": ["a1", "a2"]}')
    assert acknowledged == AlertAcknowledgedMessage(ids=["a1", "a2"])


def test_a_turn_handed_over_in_process_is_checked_like_one_from_the_broker() -> None:
    turn = turn_from_message({"utterance": "hi", "speech": "Hello.", "origin": "station",
                              "at": "2026-11-23T10:00:00+00:00"})  # fmt: skip
    assert turn.at == NOW and turn.origin == "station"
    with pytest.raises(ProtocolError) as raised:
        turn_from_message({"utterance": "hi", "speech": "Hello.", "origin": "Not An Origin"})
    assert raised.value.field == "origin"
