"""What the assistant says for each kind of announcement: prompts as data, filled in by
`sentence`, in the language people speak to it (`Names.of(fleet, locale)`). Robot and zone
names are the fleet's spoken names in that language (`Names`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from vahr.domain.fleet import SPOKEN_LOCALE, reason_said, spoken_in, zone_name_in
from vahr.domain.locale import locale_file, read_yaml

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.protocol.announcements import AnnouncementKind

# Every sentence and phrase, in en-US; another locale's are its
# `vahr/domain/locales/<locale>/announcements.yaml`, under the same names.
WORDS: dict[str, str] = {
    "stuck": "{robot} is stuck{where} and needs your help.",
    "failed": "{robot} could not finish its task: {reason}.",
    "offline": "{robot} has gone offline.",
    "waiting": "A task{for_robot} has waited {waited} in the queue.",
    "cancelled": "{robot} was given another command, so {task}{to_zone} is cancelled.",
    # A task lost for another reason (`vahr.protocol.lost_tasks.LostWhy`): `cancelled_<why>`.
    "cancelled_offline": "{robot} went offline before it started {task}{to_zone}; it is cancelled.",
    "cancelled_unacknowledged": "{robot} is not doing {task}{to_zone}, so it is cancelled.",
    "done": "{robot} has finished its task{where}.",
    "battery_low": "{robot} is low on battery and is going to charge.",
    "on_its_way": " on its way to {zone}",
    "at": " at {zone}",
    "for_robot": " for {robot}",
    "to_zone": " to {zone}",
    "no_reason": "no reason was given",
    "a_robot": "a robot",
    "minutes": "{n} minutes",
    "a_minute": "a minute",
    "seconds": "{n} seconds",
    "task_deliver": "its delivery",
    "task_navigate": "its trip",
    "task": "its task",
}
PROMPTS: dict[AnnouncementKind, str] = {
    kind: WORDS[kind]
    for kind in ("stuck", "failed", "offline", "waiting", "cancelled", "done", "battery_low")
}
NO_REASON = WORDS["no_reason"]


@dataclass(frozen=True)
class Names:
    """Spoken names of robots and zones, and the words around them, in one language; an
    unknown id is spoken as it is."""

    robots: dict[str, str]
    zones: dict[str, str]
    words: dict[str, str] = field(default_factory=lambda: dict(WORDS))

    @classmethod
    def of(cls, fleet: Fleet, locale: str = SPOKEN_LOCALE) -> Names:
        """The fleet's names in `locale` (as the skill says them), and its sentences."""
        words = dict(WORDS)
        if locale != SPOKEN_LOCALE:
            words.update(read_yaml(locale_file(locale, "announcements.yaml"), dict[str, str]))
        return cls(
            robots={robot.thing: spoken_in(robot, locale)[0] for robot in fleet.robots},
            zones={zone.id: zone_name_in(zone, locale) for zone in fleet.zones},
            words=words,
        )

    def robot(self, thing: str | None) -> str:
        return self.robots.get(thing, thing) if thing else self.words["a_robot"]

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
    why: str | None = None,
) -> str:
    """The announcement's words, first letter capitalised. For `cancelled`, `reason` is
    the task's kind (`deliver`, `navigate`) and `why` how it was lost, when not because its
    robot was sent elsewhere (`offline`, `unacknowledged`)."""
    words = names.words
    where = ""
    if zone:
        where = words["on_its_way" if kind == "stuck" else "at"].format(zone=names.zone(zone))
    # The zone a reason names by id is said by its name.
    said = reason_said(reason, zone, names.zone(zone)) if reason and zone else reason
    template = words.get(f"{kind}_{why}", words[kind]) if why else words[kind]
    text = template.format(
        robot=names.robot(thing),
        where=where,
        reason=(said or words["no_reason"]).rstrip("."),
        task=words.get(f"task_{reason}", words["task"]),
        for_robot=words["for_robot"].format(robot=names.robot(thing)) if thing else "",
        to_zone=words["to_zone"].format(zone=names.zone(zone)) if zone else "",
        waited=_duration(waited_s, words),
    )
    return text[:1].upper() + text[1:]


def _duration(seconds: float, words: dict[str, str]) -> str:
    minutes = round(seconds / 60)
    if minutes >= 2:
        return words["minutes"].format(n=minutes)
    if minutes == 1:
        return words["a_minute"]
    return words["seconds"].format(n=max(1, round(seconds)))
