"""Device shadow documents: a robot's reported state and the experiment's state.

The reported state is a contract (docs/protocol.md, Reported shadow state). `to_payload` builds
the body of a shadow `update`; `from_payload` reads the body of `get/accepted`,
`update/accepted` or `GetThingShadow`.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import msgspec

from vahr.protocol.decoding import LazyDecoder
from vahr.protocol.errors import ProtocolError, from_validation_error
from vahr.protocol.messages import ReportedPose

Status = Literal[
    "idle", "navigating", "loading", "unloading", "waiting", "stopped", "stuck", "error"
]
Result = Literal["accepted", "rejected", "done", "failed", "cancelled"]
# The experiment's weather (the paper's task II); its words and zones are `vahr.domain.weather`.
Weather = Literal["sunny", "rainy"]


class Battery(msgspec.Struct, frozen=True):
    """A robot's battery as its backend reads it: charge in percent and whether it charges."""

    percent: Annotated[int, msgspec.Meta(ge=0, le=100)]
    charging: bool = False


class LastCommand(msgspec.Struct, frozen=True):
    """The last command a robot saw and what became of it. `id` is what the skill waits for.

    Every field is sent, `null` included: a shadow update merges objects key by key, so a
    reason left out would keep the reason of an earlier command (null deletes it). `zone`
    is the zone the command was for; its `reason` names that zone by this id, which speech
    and the station replace with the zone's spoken name (`vahr.domain.fleet.reason_said`).
    """

    id: str
    action: str
    result: Result
    reason: str | None = None
    zone: str | None = None


class Reported(msgspec.Struct, frozen=True):
    """A robot's reported state. The first five fields are the contract; the rest help speech."""

    status: Status = "idle"
    zone: str | None = None
    cargo: bool = False
    last_command: LastCommand | None = None
    connected: bool = False
    # Where the current task is heading and what it is, so status can be spoken.
    destination: str | None = None
    task: str | None = None
    pose: ReportedPose | None = None
    # Reported by a backend that reads the robot's battery (nav2: sensor_msgs/BatteryState).
    battery: Battery | None = None
    # The way a robot driving on a map is taking: its planned path's points from where it
    # planned to its goal, in the map frame (`[[x, y], ...]`); None when not driving one.
    path: list[tuple[float, float]] | None = None

    def to_payload(self, client_token: str | None = None) -> bytes:
        """The body of a shadow update reporting this whole state."""
        body: dict[str, Any] = {"state": {"reported": self}}
        if client_token is not None:
            body["clientToken"] = client_token
        return msgspec.json.encode(body)


class RobotShadow(msgspec.Struct, frozen=True):
    """The parts of a robot's shadow document VAHR reads."""

    reported: Reported
    desired: dict[str, Any] | None = None
    version: int | None = None


class _State(msgspec.Struct, frozen=True):
    reported: Reported = Reported()
    desired: dict[str, Any] | None = None


class _Document(msgspec.Struct, frozen=True):
    state: _State = _State()
    version: int | None = None


class _Acknowledging(msgspec.Struct, frozen=True):
    last_command: LastCommand | None = None
    connected: bool = False


class _AcknowledgingState(msgspec.Struct, frozen=True):
    reported: _Acknowledging = _Acknowledging()


class _AcknowledgingDocument(msgspec.Struct, frozen=True):
    state: _AcknowledgingState = _AcknowledgingState()


_document_decoder: LazyDecoder[_Document] = LazyDecoder(_Document)
_acknowledging_decoder: LazyDecoder[_AcknowledgingDocument] = LazyDecoder(_AcknowledgingDocument)


def robot_shadow_from_payload(
    payload: bytes | bytearray | memoryview, *, tolerant: bool = False
) -> RobotShadow:
    """Read a robot's shadow document (get/accepted, update/accepted, GetThingShadow).

    Strict by default: any field that breaks the contract is a ProtocolError naming it.
    `tolerant` keeps what acknowledges a command when another field breaks the contract
    (a robot reporting a status this reader does not know yet must still be heard
    acknowledging), so only `last_command` and `connected` must be readable then.
    """
    # No 8 KB rule here: the state is limited, but a whole document with its metadata may be
    # larger. msgspec rejects bytes that are not UTF-8 JSON itself.
    try:
        document = _document_decoder.decode(payload)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        if not tolerant:
            raise from_validation_error(err) from err
        try:
            reported = _acknowledging_decoder.decode(payload).state.reported
        except (msgspec.ValidationError, msgspec.DecodeError):
            raise ProtocolError("payload", "the shadow holds no readable last_command") from None
        return RobotShadow(
            reported=Reported(last_command=reported.last_command, connected=reported.connected)
        )
    return RobotShadow(
        reported=document.state.reported, desired=document.state.desired, version=document.version
    )


class ExperimentState(msgspec.Struct, frozen=True, omit_defaults=True):
    """The current experiment, kept in the reported state of the experiment thing's shadow.

    The experiment runner writes it; the skill reads the weather from it (and, when none is
    set, draws one and stores it) so the person, the robots and the judge agree.
    """

    weather: Weather | None = None
    assignments: dict[str, str] = {}
    session: str | None = None

    def to_payload(self) -> bytes:
        return msgspec.json.encode({"state": {"reported": self}})


class _ExperimentStateHolder(msgspec.Struct, frozen=True):
    reported: ExperimentState = ExperimentState()


class _ExperimentDocument(msgspec.Struct, frozen=True):
    state: _ExperimentStateHolder = _ExperimentStateHolder()


def experiment_state_from_payload(payload: bytes | bytearray | memoryview) -> ExperimentState:
    try:
        document = msgspec.json.decode(bytes(payload), type=_ExperimentDocument)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise from_validation_error(err) from err
    return document.state.reported


__all__ = [
    "Battery",
    "ExperimentState",
    "LastCommand",
    "ProtocolError",
    "Reported",
    "RobotShadow",
    "ReportedPose",
    "Status",
    "Result",
    "Weather",
    "experiment_state_from_payload",
    "robot_shadow_from_payload",
]
