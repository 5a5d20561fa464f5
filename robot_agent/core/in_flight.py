"""The command a robot is running, kept on disk so a robot that dies mid-task (SIGKILL, a
power cut) reports that command `failed` when it starts again instead of leaving it
`accepted` for ever.

A command is not run again after such a restart: its id is already among the recent ids,
so a QoS 1 redelivery is ignored as a duplicate, and a half-done delivery started again from
an unknown pose could load twice. The sender learns what happened from the `failed` event
and `last_command`, and may send a new command.
"""

from __future__ import annotations

import json
import logging
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

log = logging.getLogger(__name__)

INTERRUPTED_REASON = (
    "interrupted: the robot-agent stopped without finishing it (a crash or power cut)"
)


class InFlight:
    """At most one running command (id, action), saved to `path` whenever it changes."""

    def __init__(self, path: Path | None = None) -> None:
        self.path = path
        self.current: tuple[str, str] | None = None

    def left_over(self) -> tuple[str, str] | None:
        """The command an earlier run of this robot was running when it died, if any."""
        if self.path is None or not self.path.exists():
            return None
        try:
            saved = json.loads(self.path.read_text())
            return str(saved["id"]), str(saved["action"])
        except (OSError, ValueError, TypeError, KeyError) as err:
            # A torn file must not stop the robot; it only loses this one report.
            log.warning("ignoring unreadable in-flight file %s: %s", self.path, err)
            return None

    def start(self, command_id: str, action: str) -> None:
        self.current = (command_id, action)
        self._save()

    def end(self, command_id: str) -> None:
        """Forget `command_id` if it is the running one (a newer command may have taken over)."""
        if self.current is not None and self.current[0] == command_id:
            self.current = None
            self._save()

    def clear(self) -> None:
        self.current = None
        self._save()

    def _save(self) -> None:
        if self.path is None:
            return
        try:
            if self.current is None:
                self.path.unlink(missing_ok=True)
                return
            # Write then rename, so a crash mid-write leaves the previous file intact.
            temporary = self.path.with_suffix(".tmp")
            self.path.parent.mkdir(parents=True, exist_ok=True)
            command_id, action = self.current
            temporary.write_text(json.dumps({"id": command_id, "action": action}))
            temporary.replace(self.path)
        except OSError as err:
            log.warning("cannot save the running command to %s: %s", self.path, err)
