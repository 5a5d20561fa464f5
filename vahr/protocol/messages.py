"""Command, event and presence messages (docs/protocol.md, Command: a contract).

Commands are a tagged union on `action`, so each action carries exactly its own params.
`decode_command` is the one place a command payload is validated: it raises only
`ProtocolError`, whose message names the field and the problem.
"""

from __future__ import annotations

import math
import uuid
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Annotated, Any, Literal, Protocol

import msgspec

from vahr.protocol.decoding import LazyDecoder
from vahr.protocol.errors import ProtocolError, from_validation_error, shown

if TYPE_CHECKING:
    from collections.abc import Collection


class KnownNames(Protocol):
    """What a command is checked against: the zones and robots that exist (a fleet)."""

    @property
    def zone_ids(self) -> Collection[str]: ...

    @property
    def robot_things(self) -> Collection[str]: ...


MAX_PAYLOAD_BYTES = 8 * 1024

CommandId = Annotated[str, msgspec.Meta(min_length=1, max_length=64)]
ZoneId = Annotated[str, msgspec.Meta(min_length=1, max_length=32)]
# "alexa", "console", "experiment", "robot:placebot1", ...
Source = Annotated[str, msgspec.Meta(pattern=r"^[a-z][a-z0-9_-]{0,31}(:[A-Za-z0-9:_.-]{1,128})?$")]
Timestamp = Annotated[datetime, msgspec.Meta(tz=True)]

ACTIONS = ("navigate", "deliver", "weather_delivery", "sequential_delivery", "stop", "ping")
MOTION_ACTIONS = frozenset({"navigate", "deliver", "weather_delivery", "sequential_delivery"})


def utc_now() -> datetime:
    return datetime.now(UTC)


class NoParams(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """Params of an action that takes none."""


class ZoneParams(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    zone: ZoneId


class SequentialParams(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    zone: ZoneId
    # The robot that must deliver first, or None to deliver at once.
    after: str | None


class _Command(
    msgspec.Struct, frozen=True, forbid_unknown_fields=True, tag_field="action", kw_only=True
):
    id: CommandId
    issued_at: Timestamp
    source: Source

    @property
    def action(self) -> str:
        return str(self.__struct_config__.tag)

    @property
    def is_motion(self) -> bool:
        return self.action in MOTION_ACTIONS


class Navigate(_Command, frozen=True, tag="navigate"):
    """Drive to a zone."""

    params: ZoneParams


class Deliver(_Command, frozen=True, tag="deliver"):
    """Drive to LOADING, get loaded, drive to the zone, get unloaded."""

    params: ZoneParams


class WeatherDelivery(_Command, frozen=True, tag="weather_delivery"):
    """Ask the assistant for the weather; deliver to A if sunny, C if rainy."""

    params: NoParams = NoParams()


class SequentialDelivery(_Command, frozen=True, tag="sequential_delivery"):
    """Deliver once the robot named in `after` has delivered."""

    params: SequentialParams


class Stop(_Command, frozen=True, tag="stop"):
    """Halt at once; preempts everything."""

    params: NoParams = NoParams()


class Ping(_Command, frozen=True, tag="ping"):
    """Acknowledge only."""

    params: NoParams = NoParams()


Command = Navigate | Deliver | WeatherDelivery | SequentialDelivery | Stop | Ping

_COMMAND_TYPES: dict[str, type[_Command]] = {
    "navigate": Navigate,
    "deliver": Deliver,
    "weather_delivery": WeatherDelivery,
    "sequential_delivery": SequentialDelivery,
    "stop": Stop,
    "ping": Ping,
}
_command_decoder: LazyDecoder[Command] = LazyDecoder(Command)


def new_command(
    action: str,
    params: dict[str, object] | None = None,
    *,
    source: str,
    command_id: str | None = None,
) -> Command:
    """Build a command with a fresh id and the current time, validated like a decoded one."""
    if action not in _COMMAND_TYPES:
        raise ProtocolError(
            "action", f"'{shown(action)}' is not a known action; actions are {', '.join(ACTIONS)}"
        )
    raw = {
        "id": command_id or uuid.uuid4().hex,
        "action": action,
        "params": params or {},
        "issued_at": utc_now(),
        "source": source,
    }
    try:
        return msgspec.convert(raw, Command, from_attributes=False)
    except msgspec.ValidationError as err:
        raise from_validation_error(err) from err


def check_payload(payload: bytes | bytearray | memoryview) -> bytes:
    """Apply the size and encoding rules shared by every message on the wire."""
    data = bytes(payload)
    if len(data) > MAX_PAYLOAD_BYTES:
        raise ProtocolError("payload", f"is {len(data)} bytes; the limit is {MAX_PAYLOAD_BYTES}")
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise ProtocolError("payload", f"is not valid UTF-8 (byte {err.start})") from err
    return data


def decode_command(
    payload: bytes | bytearray | memoryview, fleet: KnownNames | None = None
) -> Command:
    """Decode and validate a command; with a fleet, zones and robots must exist in it."""
    data = check_payload(payload)
    try:
        command = _command_decoder.decode(data)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        error = from_validation_error(err)
        if error.field == "action" and "not a known action" in error.reason:
            error = ProtocolError("action", f"{error.reason}; actions are {', '.join(ACTIONS)}")
        raise error from err
    if fleet is not None:
        check_against_fleet(command, fleet)
    return command


def check_against_fleet(command: Command, fleet: KnownNames) -> None:
    """Zones and peer robots named in a command must exist in the fleet."""
    params = command.params
    if isinstance(params, ZoneParams | SequentialParams) and params.zone not in fleet.zone_ids:
        zones = ", ".join(fleet.zone_ids)
        raise ProtocolError(
            "params.zone", f"'{shown(params.zone)}' is not a zone; zones are {zones}"
        )
    if isinstance(params, SequentialParams) and params.after is not None:
        if params.after not in fleet.robot_things:
            robots = ", ".join(fleet.robot_things)
            raise ProtocolError(
                "params.after", f"'{shown(params.after)}' is not a robot; robots are {robots}"
            )


EventKind = Literal[
    # The contract's events...
    "accepted",
    "rejected",
    "progress",
    "arrived",
    "loaded",
    "delivered",
    "stuck",
    "failed",
    "stopped",
    # ...and the ones that close or narrate a task.
    "done",
    "cancelled",
    "waiting",
    "said",
    "heard",
    "interpreted",
]


class ReportedPose(msgspec.Struct, frozen=True):
    """Where a robot says it is, in the `map` frame (metres, radians): in its events, its
    shadow's `reported.pose` and the fleet index. Read tolerantly, as everything a robot
    reports is; the fleet file's poses are `vahr.domain.Pose`, read strictly."""

    x: float
    y: float
    theta: float = 0.0

    def distance_to(self, other: ReportedPose) -> float:
        return math.hypot(self.x - other.x, self.y - other.y)


class Event(msgspec.Struct, frozen=True, kw_only=True, omit_defaults=True):
    """What a robot did, published on `vahr/robots/{thing}/events`.

    Only the fields that apply are sent: `zone` for arrived/loaded/delivered, `reason`
    for rejected/failed/stuck/cancelled, `progress` (0..1 of the path's length) for progress
    (with `eta_s`, seconds left, where the robot knows it, and `distance_remaining_m` from a
    backend that estimates it, such as Nav2), `text` for what was said or heard, `intent`
    and `confidence` for interpreted.
    """

    event: EventKind
    thing: str
    at: Timestamp
    command_id: str | None = None
    action: str | None = None
    zone: str | None = None
    reason: str | None = None
    progress: float | None = None
    eta_s: float | None = None
    distance_remaining_m: float | None = None
    pose: ReportedPose | None = None
    text: str | None = None
    intent: str | None = None
    confidence: float | None = None


class Presence(msgspec.Struct, frozen=True):
    """A robot's retained presence; its last will says `online: false`."""

    online: bool
    at: Timestamp


class ZoneClosures(msgspec.Struct, frozen=True):
    """The zones closed now, retained on `vahr/fleet/zones` by the dispatcher host after
    every change (`closed`: zone ids, sorted; `at`: when it was decided). No robot is sent
    into a closed zone; on a map, robots drive around a closed zone's area and leave it."""

    closed: list[str]
    at: Timestamp


_event_decoder: LazyDecoder[Event] = LazyDecoder(Event)
_closures_decoder: LazyDecoder[ZoneClosures] = LazyDecoder(ZoneClosures)
_presence_decoder: LazyDecoder[Presence] = LazyDecoder(Presence)


def _decode(decoder: LazyDecoder[Any], payload: bytes | bytearray | memoryview) -> Any:
    data = check_payload(payload)
    try:
        return decoder.decode(data)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise from_validation_error(err) from err


def decode_event(payload: bytes | bytearray | memoryview) -> Event:
    result: Event = _decode(_event_decoder, payload)
    return result


def decode_presence(payload: bytes | bytearray | memoryview) -> Presence:
    result: Presence = _decode(_presence_decoder, payload)
    return result


def decode_zone_closures(payload: bytes | bytearray | memoryview) -> ZoneClosures:
    result: ZoneClosures = _decode(_closures_decoder, payload)
    return result


def encode(message: msgspec.Struct) -> bytes:
    """The JSON bytes of any protocol message."""
    return msgspec.json.encode(message)
