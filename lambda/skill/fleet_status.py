"""The state of a whole fleet, as a status summary needs it: counts and the few robots to name.

`from_index` asks the fleet index (a handful of calls, whatever the fleet's size);
`from_shadows` builds the same from shadows already read (a small fleet, or one without
an index). Both keep, for each kind of trouble, the first `NAMED_MAX` robots by thing name:
more than a spoken summary can name within its word bound.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import msgspec

from skill.iot_fleet_index import IndexedRobot

if TYPE_CHECKING:
    from collections.abc import Sequence

    from skill.iot_fleet_index import FleetIndex
    from skill.robots import ShadowRead

_NUMBERS = re.compile(r"(\d+)")


def spoken_order(robots: Sequence[IndexedRobot]) -> list[IndexedRobot]:
    """Robots in the order a person counts them: rover 99 before rover 101 before rover 1000
    (the index returns them by thing name as text, or in an order of its own on AWS)."""

    def key(robot: IndexedRobot) -> list[tuple[int, int | str]]:
        parts = _NUMBERS.split(robot.thing)
        return [(1, int(part)) if part.isdigit() else (0, part) for part in parts]

    return sorted(robots, key=key)


# The troubles a summary names robots for, most urgent first. "error" is the status a
# robot reports when a task failed.
TROUBLES = ("stuck", "error", "offline")
NAMED_MAX = 10


class FleetState(msgspec.Struct, frozen=True):
    """How many robots report each status, how many are offline, and some of each trouble."""

    total: int
    counts: dict[str, int]
    offline: int
    troubled: dict[str, list[IndexedRobot]]

    @property
    def unreported(self) -> int:
        return max(0, self.total - sum(self.counts.values()))

    def trouble_count(self, kind: str) -> int:
        return self.offline if kind == "offline" else self.counts.get(kind, 0)


def from_index(index: FleetIndex, total: int) -> FleetState:
    """The fleet's state from the index: one aggregation, one count, and one search per
    kind of trouble that some robot has."""
    counts = index.status_counts()
    offline = index.count("shadow.reported.connected:false")
    troubled: dict[str, list[IndexedRobot]] = {}
    for kind in TROUBLES:
        found = offline if kind == "offline" else counts.get(kind, 0)
        if found:
            query = (
                "shadow.reported.connected:false"
                if kind == "offline"
                else f"shadow.reported.status:{kind}"
            )
            troubled[kind] = spoken_order(index.search(query, NAMED_MAX))
    return FleetState(total=total, counts=counts, offline=offline, troubled=troubled)


def from_shadows(reads: Sequence[ShadowRead]) -> FleetState:
    """The same from shadows read one by one (robots never reported count as unreported)."""
    robots = [
        IndexedRobot(read.thing, read.shadow.reported) for read in reads if read.shadow is not None
    ]
    counts: dict[str, int] = {}
    for robot in robots:
        counts[robot.reported.status] = counts.get(robot.reported.status, 0) + 1
    offline = [robot for robot in robots if not robot.reported.connected]
    troubled = {
        kind: spoken_order([robot for robot in robots if robot.reported.status == kind])[:NAMED_MAX]
        for kind in ("stuck", "error")
    }
    troubled["offline"] = spoken_order(offline)[:NAMED_MAX]
    return FleetState(
        total=len(reads),
        counts=counts,
        offline=len(offline),
        troubled={kind: found for kind, found in troubled.items() if found},
    )
