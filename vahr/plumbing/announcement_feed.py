"""Follow a running system's announcements from another process (`vahr console --speak`).

`AnnouncementFeed` polls `GET /vahr/announcements` (the local data plane's bounded history,
newest last) on a thread and hands each announcement it has not seen to `on_announcement`:
what was announced before it started counts as heard. Stdlib only, like `vahr say`.
"""

from __future__ import annotations

import logging
import threading
from typing import TYPE_CHECKING, Any

from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Callable

log = logging.getLogger(__name__)

POLL_S = 0.5
PATH = "/vahr/announcements"


class AnnouncementFeed:
    """Poll `api` for new announcements; `start()` and `stop()` the thread."""

    def __init__(
        self,
        api: str,
        on_announcement: Callable[[dict[str, Any]], None],
        *,
        fetch: Callable[[str, str, str], dict[str, Any]] | None = None,
        poll_s: float = POLL_S,
    ) -> None:
        from vahr.plumbing.client import call

        self._api = api
        self._on_announcement = on_announcement
        self._fetch = fetch or call
        self._poll_s = poll_s
        self._seen: set[str] = set()
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None

    def poll(self) -> list[dict[str, Any]]:
        """Fetch once; hand over and return the announcements not seen before."""
        answer = self._fetch(self._api, "GET", PATH)
        fresh = [a for a in answer.get("announcements", []) if a.get("id") not in self._seen]
        self._seen.update(a.get("id") for a in fresh)
        for announcement in fresh:
            self._on_announcement(announcement)
        return fresh

    def start(self) -> AnnouncementFeed:
        answer = self._fetch(self._api, "GET", PATH)  # the past counts as heard
        self._seen = {a.get("id") for a in answer.get("announcements", [])}
        self._thread = threading.Thread(target=self._run, name="announcements", daemon=True)
        self._thread.start()
        return self

    def _run(self) -> None:
        while not self._stopping.wait(self._poll_s):
            try:
                self.poll()
            except VahrError as err:  # the system stopped or restarts: try again
                log.debug("announcements: %s", err)

    def stop(self) -> None:
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None
