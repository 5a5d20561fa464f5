"""Fault injection into a simulated robot (development only): `vahr fault` on the local stack.

The local data plane publishes a `FaultRequest` on `vahr/dev/robots/{thing}/fault`; a
robot started with `sim.accept_faults` (as `vahr up` starts them) applies it and answers
with a `FaultAnswer` on `.../fault/answer`. A robot that is not simulated answers `ok:
false` with the reason. Topics in `topics.py`; the contract in docs/protocol.md.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import msgspec

from vahr.protocol.decoding import LazyDecoder
from vahr.protocol.errors import from_validation_error
from vahr.protocol.messages import CommandId, Timestamp, check_payload

FaultKind = Literal["stuck", "fail", "offline", "clear", "battery"]
FAULT_KINDS: tuple[FaultKind, ...] = ("stuck", "fail", "offline", "clear", "battery")
Percent = Annotated[float, msgspec.Meta(ge=0, le=100)]
# How long an `offline` robot stays away before it reconnects by itself (wall seconds).
DEFAULT_OFFLINE_S = 30.0


class FaultRequest(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """`stuck`: the robot stops where it is on its current (or next) way and never
    arrives; `fail`: its current (or next) goal aborts; `offline`: it drops its connection
    without saying goodbye (its last will says offline) for `offline_s`, then comes back;
    `clear`: faults not yet applied are forgotten; `battery`: the battery's charge is
    set to `percent`."""

    id: CommandId
    fault: FaultKind
    at: Timestamp
    offline_s: Annotated[float, msgspec.Meta(gt=0, le=3600)] = DEFAULT_OFFLINE_S
    percent: Percent | None = None


class FaultAnswer(msgspec.Struct, frozen=True, kw_only=True):
    id: CommandId
    ok: bool
    backend: str
    reason: str | None = None


def _decode(decoder: LazyDecoder[Any], payload: bytes) -> Any:
    try:
        return decoder.decode(check_payload(payload))
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise from_validation_error(err) from err


_request: LazyDecoder[FaultRequest] = LazyDecoder(FaultRequest)
_answer: LazyDecoder[FaultAnswer] = LazyDecoder(FaultAnswer)


def decode_fault_request(payload: bytes) -> FaultRequest:
    result: FaultRequest = _decode(_request, payload)
    return result


def decode_fault_answer(payload: bytes) -> FaultAnswer:
    result: FaultAnswer = _decode(_answer, payload)
    return result
