"""The commands a robot has taken and not yet ended, kept on disk so a robot that dies
(SIGKILL, a power cut) reports each of them `failed` when it starts again instead of
leaving it `accepted` for ever, or never reporting it at all.

A command is written here as it arrives, before its id is saved among the recent ids, and
removed when it ends (`done`, `failed`, `cancelled`, `rejected`). Saving the id is the
moment the robot takes the command: after it, a QoS 1 redelivery is ignored as a
duplicate. So after a restart, a command found here whose id was saved was taken and never
ended: it is reported interrupted and not run again (a half-done delivery started again
from an unknown pose could load twice). One whose id was not saved was never taken; the
broker, which had no acknowledgment for it, delivers it again and it runs then. Without
the entry written first, a robot killed between saving the id and reporting `accepted`
ignored the redelivery as a duplicate and the command was silently lost.
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
    """Commands (id -> action) taken and not ended, saved to `path` whenever they change."""

    def __init__(self, path: Path | None = None) -> None:
        self.path = path
        self.current: dict[str, str] = {}

    def left_over(self) -> list[tuple[str, str]]:
        """The commands an earlier run of this robot had not ended when it died."""
        if self.path is None or not self.path.exists():
            return []
        try:
            saved = json.loads(self.path.read_text())
            if isinstance(saved, dict):  # the one-command file of earlier versions
                saved = [saved]
            return [(str(entry["id"]), str(entry["action"])) for entry in saved]
        except (OSError, ValueError, TypeError, KeyError) as err:
            # A torn file must not stop the robot; it only loses these reports.
            log.warning("ignoring unreadable in-flight file %s: %s", self.path, err)
            return []

    def start(self, command_id: str, action: str) -> None:
        if self.current.get(command_id) != action:
            self.current[command_id] = action
            self._save()

    def end(self, command_id: str) -> None:
        """Forget `command_id` (nothing happens if it is not here)."""
        if self.current.pop(command_id, None) is not None:
            self._save()

    def clear(self) -> None:
        self.current = {}
        self._save()

    def _save(self) -> None:
        if self.path is None:
            return
        try:
            if not self.current:
                self.path.unlink(missing_ok=True)
                return
            # Write then rename, so a crash mid-write leaves the previous file intact.
            temporary = self.path.with_suffix(".tmp")
            self.path.parent.mkdir(parents=True, exist_ok=True)
            entries = [{"id": i, "action": a} for i, a in self.current.items()]
            temporary.write_text(json.dumps(entries))
            temporary.replace(self.path)
        except OSError as err:
            log.warning("cannot save the running commands to %s: %s", self.path, err)
