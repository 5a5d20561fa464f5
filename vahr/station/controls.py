"""The keyboard-and-mouse panel's orders, as the paper's baseline offered them.

A robot is sent to a zone (`navigate`; the arms load and unload on arrival) or stopped, one
robot or all at once; nothing else, so the panel can never send a compound command. A zone
is closed or opened at the dispatcher (`change_zone`, the zones card): a change to the
whole fleet's service, a supervisor's. Each
order goes out on the robot's (or the fleet's) command topic with `source: "console"`,
exactly as `vahr experiment`'s observer console sends it, and is checked first against the
operator's role (`vahr.domain.people`: sending a robot is a command, stopping is anyone's)
and the running session's procedure (`Desk.check_order`). Every order, sent or refused, is
recorded in the audit trail with the operator (channel `station-panel`).
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

from vahr.domain.people import OPEN, Person, may
from vahr.protocol import ProtocolError, encode, new_command, topics
from vahr.protocol.audit import AuditEntry, Outcome, now
from vahr.station.errors import RequestError

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain import Fleet
    from vahr.domain.people import ActionKind
    from vahr.protocol import Command
    from vahr.station.desk import Desk

log = logging.getLogger(__name__)

SOURCE = "console"
CHANNEL = "station-panel"
# Who works the panel where nobody signs in: everyone may do everything, as a supervisor.
ANYONE = OPEN.person("station")
# What each role may do at the panel, said when it asked for more.
REFUSED = "{name} is {role}, who may {may}. Nothing was sent."
ROLE_NAMES = {"viewer": "a viewer", "operator": "an operator", "supervisor": "a supervisor"}
MAY = {
    "viewer": "watch the robots, ask about them and stop them, but not send them",
    "operator": "send and stop robots",
    "supervisor": "do everything",
}


class Controls:
    """Send the panel's orders; every method returns the command's id. `record` takes the
    trail's entry for each order (None: not recorded)."""

    def __init__(
        self,
        fleet: Fleet,
        desk: Desk,
        publish: Callable[[str, bytes], None],
        record: Callable[[AuditEntry], object] | None = None,
    ) -> None:
        self.fleet = fleet
        self.desk = desk
        self._publish = publish
        self._record = record

    def navigate(self, thing: str, zone: str, operator: Person = ANYONE) -> str:
        self._check_robot(thing)
        if zone not in self.fleet.zone_ids:
            raise ProtocolError(
                "zone", f"{zone!r} is not a zone; zones are {', '.join(self.fleet.zone_ids)}"
            )
        words = f"navigate {thing} to {zone}"
        self._allow(operator, "command", words, [thing], {"robot": thing, "zone": zone})
        self.desk.check_order("navigate")
        command = new_command("navigate", {"zone": zone}, source=SOURCE)
        self._send(topics.robot_cmd(thing), command, operator, words, [thing], {"zone": zone})
        return command.id

    def stop(self, thing: str | None, operator: Person = ANYONE) -> str:
        """Stop one robot, or (None) every robot with one message on the fleet topic."""
        if thing is not None:
            self._check_robot(thing)
        self.desk.check_order("stop")
        command = new_command("stop", source=SOURCE)
        topic = topics.robot_cmd(thing) if thing is not None else topics.FLEET_CMD
        robots = [thing] if thing is not None else list(self.fleet.robot_things)
        words = f"stop {thing}" if thing is not None else "stop all"
        self._send(topic, command, operator, words, robots, {})
        return command.id

    def change_zone(
        self,
        zone: str,
        closed: bool,
        operator: Person,
        change: Callable[[], dict[str, Any]],
    ) -> dict[str, Any]:
        """Close or open `zone` by calling `change` (the dispatcher's answer, a `ZoneChange`
        as JSON) once the operator's role allows it; the queued tasks an opening gave to
        robots are recorded with it."""
        words = f"{'close' if closed else 'open'} zone {zone}"
        slots: dict[str, str | None] = {"zone": zone}
        self._allow(operator, "fleet", words, [], slots)
        try:
            answer = change()
        except Exception as err:
            self._note(operator, words, "failed", [], slots, reason=str(err))
            raise
        given = [task for task in answer.get("given", []) if isinstance(task, dict)]
        robots = [str(task["thing"]) for task in given if task.get("thing")]
        commands = [str(task["id"]) for task in given if task.get("id")]
        self._note(operator, words, "sent", robots, slots, *commands)
        return answer

    def _allow(
        self,
        operator: Person,
        kind: ActionKind,
        words: str,
        robots: list[str],
        slots: dict[str, str | None],
    ) -> None:
        """Refuse (and record) an order the operator's role does not allow."""
        if may(operator.role, kind):
            return
        role = operator.role
        refusal = REFUSED.format(name=operator.shown, role=ROLE_NAMES[role], may=MAY[role])
        self._note(operator, words, "refused", robots=[], slots=slots, reason=refusal)
        raise RequestError(403, refusal)

    def _send(
        self,
        topic: str,
        command: Command,
        operator: Person,
        words: str,
        robots: list[str],
        slots: dict[str, str | None],
    ) -> None:
        try:
            self._publish(topic, encode(command))
        except Exception as err:
            self._note(operator, words, "failed", robots, slots, command.id, reason=str(err))
            raise
        self._note(operator, words, "sent", robots, slots, command.id)

    def _note(
        self,
        operator: Person,
        words: str,
        outcome: Outcome,
        robots: list[str],
        slots: dict[str, str | None],
        *commands: str,
        reason: str | None = None,
    ) -> None:
        """The order's record in the trail; a trail that cannot take it is logged, and the
        order stands."""
        if self._record is None:
            return
        entry = AuditEntry(
            time=now(),
            who=operator.id,
            name=operator.name,
            role=operator.role,
            channel=CHANNEL,
            words=words,
            intent=words.split(" ", 1)[0],
            slots=slots,
            robots=robots,
            commands=list(commands),
            outcome=outcome,
            reason=reason,
        )
        try:
            self._record(entry)
        except Exception:
            log.exception("the audit trail did not take the panel's %s", words)

    def _check_robot(self, thing: str) -> None:
        if thing not in self.fleet.robot_things:
            raise ProtocolError(
                "robot",
                f"{thing!r} is not a robot; robots are {', '.join(self.fleet.robot_things)}",
            )
