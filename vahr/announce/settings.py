"""The announcer's settings: one typed struct, validated once, read from one place.

The local stack uses the defaults; the cloud's announcer function reads the same struct
as JSON from its environment (`VAHR_ANNOUNCE_SETTINGS`, written by the CDK stack from the
`announce` context object in cdk.json). Errors name the field and the reason.
"""

from __future__ import annotations

from typing import Annotated, Any

import msgspec

from vahr.protocol.announcements import ANNOUNCEMENT_KINDS, AnnouncementKind
from vahr.protocol.errors import ProtocolError, from_validation_error

Seconds = Annotated[float, msgspec.Meta(ge=0, le=7 * 24 * 3600)]
PositiveSeconds = Annotated[float, msgspec.Meta(gt=0, le=24 * 3600)]
Priority = Annotated[int, msgspec.Meta(ge=0, le=9)]
# Who an announcement is for: `everyone` (Alexa's Multicast: every user who enabled the
# skill's notifications) or one person's Alexa user id (Unicast).
Person = Annotated[
    str, msgspec.Meta(pattern=r"^(everyone|amzn1\.ask\.account\.[A-Za-z0-9._-]{1,400})$")
]

EVERYONE = "everyone"


def _default_priorities() -> dict[AnnouncementKind, int]:
    # Stuck and offline first (a robot that needs a hand or has vanished), then a failed
    # task or one the fleet gave up (its robot was sent elsewhere by name), then a task kept
    # waiting, and a finished task last.
    return {
        "stuck": 3,
        "offline": 3,
        "failed": 2,
        "cancelled": 2,
        "battery_low": 2,
        "waiting": 1,
        "done": 0,
    }


class AnnounceSettings(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """What to tell, how often, and to whom."""

    # The kinds worth telling; `done` is off by default (the person asked for the task and
    # the skill already confirmed it).
    kinds: list[AnnouncementKind] = msgspec.field(
        default_factory=lambda: [
            "stuck",
            "failed",
            "offline",
            "waiting",
            "cancelled",
            "battery_low",
        ]
    )
    priorities: dict[AnnouncementKind, Priority] = msgspec.field(
        default_factory=_default_priorities
    )
    # At most this many announcements per person in any `window_s` seconds.
    max_per_window: Annotated[int, msgspec.Meta(ge=1, le=100)] = 4
    window_s: PositiveSeconds = 60.0
    # Kinds below this priority leave `reserve_for_urgent` of the window to the ones at or
    # above it, so a burst of finished tasks never delays a stuck robot.
    urgent_priority: Priority = 2
    reserve_for_urgent: Annotated[int, msgspec.Meta(ge=0, le=99)] = 1
    # A robot offline for less than this (a restart) is not worth telling.
    offline_grace_s: Seconds = 0.0
    # A queued task that has waited longer than this is worth telling.
    queue_wait_s: PositiveSeconds = 300.0
    # What the rate limit holds back is told later, never dropped for its age. To keep the
    # memory (and the cloud's one state item) bounded, at most this many wait at once; past
    # it the last in line (lowest priority, newest) is dropped, logged and counted.
    max_held: Annotated[int, msgspec.Meta(ge=1, le=5000)] = 500
    # thing -> person; robots not named go to `default_person`.
    audience: dict[str, Person] = msgspec.field(default_factory=dict)
    default_person: Person = EVERYONE
    # How many announcements the local data plane keeps (`GET /vahr/announcements`).
    history: Annotated[int, msgspec.Meta(ge=1, le=10_000)] = 200

    def __post_init__(self) -> None:
        missing = [kind for kind in ANNOUNCEMENT_KINDS if kind not in self.priorities]
        if missing:
            raise ProtocolError("priorities", f"needs a priority for {', '.join(missing)}")
        if self.reserve_for_urgent >= self.max_per_window:
            raise ProtocolError(
                "reserve_for_urgent",
                f"{self.reserve_for_urgent} must be less than max_per_window "
                f"({self.max_per_window}), or nothing but urgent news is ever told",
            )

    def priority(self, kind: AnnouncementKind) -> int:
        return self.priorities[kind]

    def person_for(self, thing: str | None) -> str:
        return self.audience.get(thing, self.default_person) if thing else self.default_person


def settings_from(raw: Any) -> AnnounceSettings:
    """Validate a mapping (or JSON text/bytes) into settings; ProtocolError names the field."""
    try:
        if isinstance(raw, str | bytes):
            return msgspec.json.decode(raw or b"{}", type=AnnounceSettings)
        return msgspec.convert(raw or {}, AnnounceSettings)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        if isinstance(err.__cause__, ProtocolError):  # a rule across fields (__post_init__)
            raise err.__cause__ from err
        raise from_validation_error(err) from err
