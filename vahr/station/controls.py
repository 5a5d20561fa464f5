"""The keyboard-and-mouse panel's orders, as the paper's baseline offered them.

A robot is sent to a zone (`navigate`; the arms load and unload on arrival) or stopped, one
robot or all at once; nothing else, so the panel can never send a compound command. Each
order goes out on the robot's (or the fleet's) command topic with `source: "console"`,
exactly as `vahr experiment`'s observer console sends it, and is checked first against the
running session's procedure (`Desk.check_order`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.protocol import ProtocolError, encode, new_command, topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain import Fleet
    from vahr.station.desk import Desk

SOURCE = "console"


class Controls:
    """Send the panel's orders; every method returns the command's id."""

    def __init__(self, fleet: Fleet, desk: Desk, publish: Callable[[str, bytes], None]) -> None:
        self.fleet = fleet
        self.desk = desk
        self._publish = publish

    def navigate(self, thing: str, zone: str) -> str:
        self._check_robot(thing)
        if zone not in self.fleet.zone_ids:
            raise ProtocolError(
                "zone", f"{zone!r} is not a zone; zones are {', '.join(self.fleet.zone_ids)}"
            )
        self.desk.check_order("navigate")
        command = new_command("navigate", {"zone": zone}, source=SOURCE)
        self._publish(topics.robot_cmd(thing), encode(command))
        return command.id

    def stop(self, thing: str | None) -> str:
        """Stop one robot, or (None) every robot with one message on the fleet topic."""
        if thing is not None:
            self._check_robot(thing)
        self.desk.check_order("stop")
        command = new_command("stop", source=SOURCE)
        topic = topics.robot_cmd(thing) if thing is not None else topics.FLEET_CMD
        self._publish(topic, encode(command))
        return command.id

    def _check_robot(self, thing: str) -> None:
        if thing not in self.fleet.robot_things:
            raise ProtocolError(
                "robot",
                f"{thing!r} is not a robot; robots are {', '.join(self.fleet.robot_things)}",
            )
