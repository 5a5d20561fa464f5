"""The ids of the commands the skill published during a turn, seen at the data plane."""

from __future__ import annotations

import json
import threading

from vahr.protocol import topics


class CommandLog:
    """Record command ids published to robot or fleet command topics; `take()` drains."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._ids: list[str] = []

    def observe(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        if topic != topics.FLEET_CMD and (parsed is None or parsed[1] != "cmd"):
            return
        try:
            command_id = json.loads(payload).get("id")
        except (ValueError, AttributeError, RecursionError):
            return
        if isinstance(command_id, str):
            with self._lock:
                self._ids.append(command_id)

    def take(self) -> list[str]:
        with self._lock:
            taken, self._ids = self._ids, []
        return taken
