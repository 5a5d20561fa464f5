"""Which command goes to which topic, and which robots must acknowledge it (pure logic).

A command to one robot goes to `vahr/robots/{thing}/cmd`; a command to the whole fleet is
published once to `vahr/fleet/cmd`, and every robot then reports the same command id.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from skill.vocabulary import FLEET
from vahr.protocol import check_against_fleet, new_command, topics

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.protocol import Command

SOURCE = "alexa"


class Publication(msgspec.Struct, frozen=True):
    """One publish: the topic, the command, and the robots expected to acknowledge it."""

    topic: str
    command: Command
    recipients: tuple[str, ...]
    target: str  # a thing name, or FLEET

    @property
    def to_fleet(self) -> bool:
        return self.target == FLEET


def publication(
    fleet: Fleet, action: str, target: str, params: dict[str, object] | None = None
) -> Publication:
    """A fresh command for one robot or (target `all`) for the whole fleet."""
    command = new_command(action, params, source=SOURCE)
    check_against_fleet(command, fleet)
    if target == FLEET:
        return Publication(topics.FLEET_CMD, command, fleet.robot_things, FLEET)
    fleet.robot(target)  # KeyError for a robot the fleet does not have
    return Publication(topics.robot_cmd(target), command, (target,), target)


def sequential(
    fleet: Fleet, first: str, first_zone: str, second: str, second_zone: str
) -> tuple[Publication, Publication]:
    """Task III: `first` delivers at once; `second` delivers once `first` has delivered."""
    if first == second or FLEET in (first, second):
        raise ValueError("a sequential delivery needs two different robots")
    return (
        publication(fleet, "sequential_delivery", first, {"zone": first_zone, "after": None}),
        publication(fleet, "sequential_delivery", second, {"zone": second_zone, "after": first}),
    )
