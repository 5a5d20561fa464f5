"""What the assistant says for each kind of announcement: prompts as data, filled in by
`sentence`. Robot and zone names are the fleet's spoken names (`Names`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from vahr.domain.fleet import reason_said, zone_phrase

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.protocol.announcements import AnnouncementKind

PROMPTS: dict[AnnouncementKind, str] = {
    "stuck": "{robot} is stuck{where} and needs your help.",
    "failed": "{robot} could not finish its task: {reason}.",
    "offline": "{robot} has gone offline.",
    "waiting": "A task{for_robot} has waited {waited} in the queue.",
    "cancelled": "{robot} was given another command, so its {reason}{to_zone} is cancelled.",
    "done": "{robot} has finished its task{where}.",
}
NO_REASON = "no reason was given"


@dataclass(frozen=True)
class Names:
    """Spoken names of robots and zones; an unknown id is spoken as it is."""

    robots: dict[str, str]
    zones: dict[str, str]

    @classmethod
    def of(cls, fleet: Fleet) -> Names:
        return cls(
            robots={robot.thing: robot.spoken[0] for robot in fleet.robots},
            zones={zone.id: zone_phrase(zone) for zone in fleet.zones},
        )

    def robot(self, thing: str | None) -> str:
        return self.robots.get(thing, thing) if thing else "a robot"

    def zone(self, zone_id: str) -> str:
        return self.zones.get(zone_id, f"zone {zone_id}")


def sentence(
    kind: AnnouncementKind,
    names: Names,
    *,
    thing: str | None,
    reason: str | None = None,
    zone: str | None = None,
    waited_s: float = 0.0,
) -> str:
    """The announcement's words, first letter capitalised."""
    where = ""
    if zone:
        where = (
            f" on its way to {names.zone(zone)}" if kind == "stuck" else f" at {names.zone(zone)}"
        )
    # The zone a reason names by id is said by its name.
    said = reason_said(reason, zone, names.zone(zone)) if reason and zone else reason
    text = PROMPTS[kind].format(
        robot=names.robot(thing),
        where=where,
        reason=(said or NO_REASON).rstrip("."),
        for_robot=f" for {names.robot(thing)}" if thing else "",
        to_zone=f" to {names.zone(zone)}" if zone else "",
        waited=_duration(waited_s),
    )
    return text[:1].upper() + text[1:]


def _duration(seconds: float) -> str:
    minutes = round(seconds / 60)
    if minutes >= 2:
        return f"{minutes} minutes"
    if minutes == 1:
        return "a minute"
    return f"{max(1, round(seconds))} seconds"
