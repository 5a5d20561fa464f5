"""The ids of the commands the skill published during a turn, seen at the data plane."""

from __future__ import annotations

import json
import threading

from vahr.protocol import topics


class CommandLog:
    """Record command ids published to robot or fleet command topics; `take()` drains.

    A turn's commands are those whose publish began and succeeded since the last `take()`
    (the turn's start). A publish that began in an earlier turn and was acknowledged only
    now (the skill gave up on it after its own timeout and said it could not reach the
    robot) belongs to no turn: counted here, it was named as the next turn's command, for
    that turn's robots, which never received it. A retried publish of one command is
    named once.

    `starts_seen`: the caller reports each publish's start with `begin()` (the local data
    plane does; a log fed from the broker alone sees only what was published).
    """

    def __init__(self, *, starts_seen: bool = False) -> None:
        self._starts_seen = starts_seen
        self._lock = threading.Lock()
        self._begun: set[str] = set()
        self._ids: list[str] = []

    def begin(self, topic: str, payload: bytes) -> None:
        """A publish request arrived at the data plane (before it is sent to the broker)."""
        command_id = _command_id(topic, payload)
        if command_id is not None:
            with self._lock:
                self._begun.add(command_id)

    def observe(self, topic: str, payload: bytes) -> None:
        """A publish succeeded (the broker acknowledged it)."""
        command_id = _command_id(topic, payload)
        if command_id is None:
            return
        with self._lock:
            if command_id in self._ids:
                return
            if command_id in self._begun or not self._starts_seen:
                self._ids.append(command_id)

    def take(self) -> list[str]:
        with self._lock:
            taken, self._ids = self._ids, []
            self._begun = set()
        return taken


def _command_id(topic: str, payload: bytes) -> str | None:
    parsed = topics.parse_robot_topic(topic)
    if topic != topics.FLEET_CMD and (parsed is None or parsed[1] != "cmd"):
        return None
    try:
        command_id = json.loads(payload).get("id")
    except (ValueError, AttributeError, RecursionError):
        return None
    return command_id if isinstance(command_id, str) else None
