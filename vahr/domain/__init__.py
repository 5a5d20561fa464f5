"""The domain: the fleet (robots, zones, groups, the floor), its poses, the languages VAHR
speaks, the weather words, and how people address the assistant.

Import from here: the fleet model (`Fleet`, `load_fleet`, `Robot`, `Zone`, `Group`, `Pose`,
`Floor`) and the weathers (`WEATHERS`, `WEATHER_ZONES`); `text`, `locale`, `weather` and
`invocation` are modules of their own. Every Lambda imports it: msgspec, and PyYAML lazily
when a fleet file is read. It sits on the wire contract (`vahr.protocol`) and nothing else.
"""

from __future__ import annotations

from vahr.domain.fleet import (
    DEFAULT_FLEET_FILE,
    FLEET_GROUP,
    FLEET_GROUP_NAMES,
    Confirmation,
    Conveyor,
    Fleet,
    Floor,
    Group,
    Point,
    Pose,
    Robot,
    Segment,
    Zone,
    load_fleet,
)
from vahr.domain.weather import WEATHER_ZONES, WEATHERS

__all__ = [
    "DEFAULT_FLEET_FILE",
    "FLEET_GROUP",
    "FLEET_GROUP_NAMES",
    "WEATHERS",
    "WEATHER_ZONES",
    "Confirmation",
    "Conveyor",
    "Fleet",
    "Floor",
    "Group",
    "Point",
    "Pose",
    "Robot",
    "Segment",
    "Zone",
    "load_fleet",
]
