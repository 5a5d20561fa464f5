"""The command, event and presence messages: round trips and the one error type."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from typing import TYPE_CHECKING

import pytest

from vahr.protocol import (
    MAX_PAYLOAD_BYTES,
    Deliver,
    Event,
    Navigate,
    Presence,
    ProtocolError,
    ReportedPose,
    SequentialDelivery,
    Stop,
    decode_command,
    decode_event,
    decode_presence,
    encode,
    new_command,
)

if TYPE_CHECKING:
    from vahr.domain import Fleet

AT = "2026-11-22T10:00:00Z"


def command(**overrides: object) -> bytes:
    body: dict[str, object] = {
        "id": "c-1",
        "action": "navigate",
        "params": {"zone": "A"},
        "issued_at": AT,
        "source": "alexa",
    }
    body.update(overrides)
    return json.dumps({k: v for k, v in body.items() if v is not ...}).encode()


@pytest.mark.parametrize(
    ("action", "params"),
    [
        ("navigate", {"zone": "B"}),
        ("deliver", {"zone": "D"}),
        ("weather_delivery", {}),
        ("sequential_delivery", {"zone": "D", "after": "placebot1"}),
        ("sequential_delivery", {"zone": "D", "after": None}),
        ("stop", {}),
        ("ping", {}),
    ],
)
def test_every_action_round_trips(fleet: Fleet, action: str, params: dict[str, object]) -> None:
    sent = new_command(action, params, source="console")
    wire = json.loads(encode(sent))
    assert wire["action"] == action
    assert wire["params"] == params
    assert wire["issued_at"].endswith("Z")
    assert decode_command(encode(sent), fleet) == sent


def test_decoded_command_is_typed_by_action(fleet: Fleet) -> None:
    assert isinstance(decode_command(command(), fleet), Navigate)
    assert isinstance(decode_command(command(action="deliver"), fleet), Deliver)
    assert isinstance(decode_command(command(action="stop", params={}), fleet), Stop)
    seq = decode_command(
        command(action="sequential_delivery", params={"zone": "D", "after": "placebot1"}), fleet
    )
    assert isinstance(seq, SequentialDelivery)
    assert seq.params.after == "placebot1"
    assert seq.is_motion


def test_actions_without_params_accept_an_omitted_params(fleet: Fleet) -> None:
    assert decode_command(command(action="ping", params=...), fleet).action == "ping"


def test_event_and_presence_round_trip() -> None:
    event = Event(
        event="arrived",
        thing="placebot1",
        at=datetime(2026, 11, 22, tzinfo=UTC),
        command_id="c-1",
        action="navigate",
        zone="A",
        pose=ReportedPose(x=9.0, y=7.0),
    )
    wire = json.loads(encode(event))
    assert "reason" not in wire  # only the fields that apply are sent
    assert decode_event(encode(event)) == event
    presence = Presence(online=False, at=datetime(2026, 11, 22, tzinfo=UTC))
    assert decode_presence(encode(presence)) == presence


_NESTED_JUNK = {"zone": {"a": [{"b": [1, 2, {"c": None}]}]}}

MALFORMED: list[tuple[str, bytes, str]] = [
    ("unknown action", command(action="fly"), "action"),
    ("action not a string", command(action=3), "action"),
    ("action missing", command(action=...), "action"),
    ("action null", command(action=None), "action"),
    ("id missing", command(id=...), "id"),
    ("id empty", command(id=""), "id"),
    ("id too long", command(id="x" * 65), "id"),
    ("id a number", command(id=7), "id"),
    ("issued_at missing", command(issued_at=...), "issued_at"),
    ("issued_at not a time", command(issued_at="yesterday"), "issued_at"),
    ("issued_at without zone", command(issued_at="2026-11-22T10:00:00"), "issued_at"),
    ("issued_at a number", command(issued_at=1700000000), "issued_at"),
    ("source missing", command(source=...), "source"),
    ("source malformed", command(source="Alexa Echo!"), "source"),
    ("source a list", command(source=["alexa"]), "source"),
    ("unknown top-level field", command(priority="high"), "priority"),
    ("params missing", command(params=...), "params"),
    ("params a list", command(params=["A"]), "params"),
    ("params a string", command(params="A"), "params"),
    ("zone missing", command(params={}), "params.zone"),
    ("zone not a zone", command(params={"zone": "E"}), "params.zone"),
    ("zone lower case", command(params={"zone": "a"}), "params.zone"),
    ("zone a number", command(params={"zone": 1}), "params.zone"),
    ("zone null", command(params={"zone": None}), "params.zone"),
    ("zone nested junk", command(params=_NESTED_JUNK), "params.zone"),
    ("unknown param", command(params={"zone": "A", "speed": 9}), "params.speed"),
    ("deliver to nowhere", command(action="deliver", params={"zone": "Z"}), "params.zone"),
    ("stop with params", command(action="stop", params={"zone": "A"}), "params.zone"),
    (
        "sequential without after",
        command(action="sequential_delivery", params={"zone": "D"}),
        "params.after",
    ),
    (
        "sequential after unknown robot",
        command(action="sequential_delivery", params={"zone": "D", "after": "r2d2"}),
        "params.after",
    ),
    (
        "sequential after a number",
        command(action="sequential_delivery", params={"zone": "D", "after": 2}),
        "params.after",
    ),
    ("not JSON", b"navigate to A", "payload"),
    ("truncated JSON", command()[:-5], "payload"),
    ("JSON array", b'[{"action": "navigate"}]', "payload"),
    ("JSON string", b'"navigate"', "payload"),
    ("JSON null", b"null", "payload"),
    ("empty payload", b"", "payload"),
    ("invalid UTF-8", b'{"id": "\xff\xfe", "action": "ping"}', "payload"),
    (
        "oversize",
        command(
            id="big", source="console:" + "x" * 100, params={"zone": "A" * (MAX_PAYLOAD_BYTES)}
        ),
        "payload",
    ),
]


@pytest.mark.parametrize(
    ("case", "payload", "field"), MALFORMED, ids=[case for case, _, _ in MALFORMED]
)
def test_malformed_commands_are_rejected_naming_the_field(
    fleet: Fleet, case: str, payload: bytes, field: str
) -> None:
    with pytest.raises(ProtocolError) as raised:
        decode_command(payload, fleet)
    assert raised.value.field == field, str(raised.value)
    assert str(raised.value).startswith(f"{field}: ")
    assert "\n" not in str(raised.value)


def test_bad_zone_message_lists_the_zones(fleet: Fleet) -> None:
    with pytest.raises(
        ProtocolError, match=r"^params\.zone: 'E' is not a zone; zones are LOADING, A, B, C, D$"
    ):
        decode_command(command(params={"zone": "E"}), fleet)


def test_unknown_action_message_lists_the_actions(fleet: Fleet) -> None:
    with pytest.raises(
        ProtocolError, match=r"^action: 'fly' is not a known action; actions are navigate, deliver"
    ):
        decode_command(command(action="fly"), fleet)


def test_new_command_validates_like_decoding() -> None:
    with pytest.raises(ProtocolError, match=r"^params\.zone: is required"):
        new_command("navigate", {}, source="alexa")
    with pytest.raises(ProtocolError, match=r"^action: "):
        new_command("dance", {}, source="alexa")


def test_fresh_ids_are_unique() -> None:
    ids = {new_command("ping", source="console").id for _ in range(1000)}
    assert len(ids) == 1000
