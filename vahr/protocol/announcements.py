"""An announcement: what the assistant tells the person without being asked (issue 34).

The policy that decides what is worth telling is `vahr.announce`; this is the message it
produces, the same on every path: `GET /vahr/announcements` on the local data plane, the
`vahr/assistant/announcements` topic, the console that speaks it, the station that shows
it, and the cloud's announcer function (whose Proactive Events `referenceId` is `id`).
"""

from __future__ import annotations

from typing import Annotated, Literal

import msgspec

from vahr.protocol.decoding import LazyDecoder
from vahr.protocol.errors import from_validation_error
from vahr.protocol.messages import Timestamp, check_payload

# `battery_low`: a robot low on charge is going to a charger by itself.
AnnouncementKind = Literal[
    "stuck", "failed", "offline", "waiting", "cancelled", "done", "battery_low"
]
ANNOUNCEMENT_KINDS: tuple[AnnouncementKind, ...] = (
    "stuck",
    "failed",
    "offline",
    "waiting",
    "cancelled",
    "done",
    "battery_low",
)
# Alexa's referenceId allows letters, digits and '~', 1 to 100 characters.
ReferenceId = Annotated[str, msgspec.Meta(pattern=r"^[A-Za-z0-9~]{1,100}$")]


class Announcement(msgspec.Struct, frozen=True, kw_only=True):
    """One thing the assistant said unprompted.

    `id` is stable for one fault (a retry of the same announcement carries the same id),
    `time` is when it was announced and `opened_at` when the fault began, so the delay
    between them is what the rate limit cost. `thing` is None only for a queued task that
    names no robot. `person` is who it is for (`everyone`, or an Alexa user id).
    """

    id: ReferenceId
    time: Timestamp
    thing: str | None
    kind: AnnouncementKind
    priority: int
    speech: str
    reason: str | None = None
    person: str = "everyone"
    opened_at: Timestamp


_decoder: LazyDecoder[Announcement] = LazyDecoder(Announcement)


def decode_announcement(payload: bytes | bytearray | memoryview) -> Announcement:
    """Decode and validate an announcement; raises ProtocolError naming the field."""
    data = check_payload(payload)
    try:
        return _decoder.decode(data)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise from_validation_error(err) from err


def announcement_json(announcement: Announcement) -> dict[str, object]:
    """The announcement as the data plane's JSON object (times as RFC 3339 strings)."""
    as_json: dict[str, object] = msgspec.to_builtins(announcement)
    return as_json
