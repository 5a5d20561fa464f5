"""The ids of recently executed commands, kept on disk so a QoS 1 redelivery after a
restart still runs once (docs/protocol.md: the same `id` twice is executed once)."""

from __future__ import annotations

import json
import logging
from collections import OrderedDict
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

log = logging.getLogger(__name__)


class RecentIds:
    """A bounded, insertion-ordered set of command ids, saved to `path` after each change."""

    def __init__(self, path: Path | None = None, capacity: int = 1000) -> None:
        self.path = path
        self.capacity = capacity
        self._ids: OrderedDict[str, None] = OrderedDict()
        if path is not None and path.exists():
            try:
                saved = json.loads(path.read_text())
                for command_id in saved[-capacity:]:
                    self._ids[str(command_id)] = None
            except (OSError, ValueError, TypeError) as err:
                # A torn or foreign file must not stop the robot; it only weakens dedup.
                log.warning("ignoring unreadable recent-id file %s: %s", path, err)

    def __contains__(self, command_id: object) -> bool:
        return command_id in self._ids

    def __len__(self) -> int:
        return len(self._ids)

    def add(self, command_id: str) -> bool:
        """Remember `command_id`; False if it was already known (a duplicate)."""
        if command_id in self._ids:
            return False
        self._ids[command_id] = None
        while len(self._ids) > self.capacity:
            self._ids.popitem(last=False)
        self._save()
        return True

    def _save(self) -> None:
        if self.path is None:
            return
        # Write then rename, so a crash mid-write leaves the previous file intact.
        temporary = self.path.with_suffix(".tmp")
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            temporary.write_text(json.dumps(list(self._ids)))
            temporary.replace(self.path)
        except OSError as err:
            # The command is remembered in memory and must still run; a full or read-only
            # disk only weakens de-duplication across a restart.
            log.warning("cannot save recent command ids to %s: %s", self.path, err)
