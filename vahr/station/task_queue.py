"""The fleet's task queue for the station: read from the dispatcher and relayed to the pages;
and the station's switch that closes and opens zones there.

The dispatcher serves the queue at `GET {api}/vahr/tasks` (`{"tasks": [...], "closed": [zone
ids], "out_of_service": [things]}`) and closes a zone at `POST {api}/vahr/zones/{zone}`
(`ZoneSwitch`). A `TaskPoller` reads it every `EVERY_S` on its own thread and hands it to
the feed, which sends it to the pages only when it changed (`Feed.set_tasks`): the page
never polls, and however many pages are open the dispatcher is asked once a period. A
deployment without a dispatcher (a 404) shows the queue as not available; an unreachable or
unreadable answer leaves the last queue shown, and is logged as a warning the first time
only (a busy data plane that answers late now and then would otherwise fill the station's
log).
"""

from __future__ import annotations

import logging
import urllib.error
import urllib.request
from typing import TYPE_CHECKING
from urllib.parse import quote

import msgspec

from vahr.dispatch import Task  # noqa: TC001 (msgspec reads it at run time)
from vahr.protocol.audit import RECORDED_BY_HEADER
from vahr.station.errors import RequestError
from vahr.station.page_messages import TasksMessage
from vahr.station.polling import Poller

if TYPE_CHECKING:
    from vahr.station.feed import Feed

log = logging.getLogger(__name__)

EVERY_S = 1.0
TIMEOUT_S = 2.0
# A queue longer than this is cut to its first tasks (queued and assigned ones come first
# in the dispatcher's order, which is the line).
TASKS_SHOWN = 200


class _Tasks(msgspec.Struct):
    tasks: list[Task]
    closed: list[str] = []
    out_of_service: list[str] = []


_decoder = msgspec.json.Decoder(_Tasks)


def read_tasks(url: str, timeout_s: float = TIMEOUT_S) -> TasksMessage:
    """The queue at `url`; not available when nothing answers there (HTTP 404).
    Raises `OSError` or `msgspec.MsgspecError` when it cannot be read."""
    try:
        with urllib.request.urlopen(url, timeout=timeout_s) as answer:  # noqa: S310 (http only)
            body = answer.read()
    except urllib.error.HTTPError as err:
        if err.code == 404:
            return TasksMessage(tasks=[], available=False)
        raise
    answer = _decoder.decode(body)
    return TasksMessage(
        tasks=answer.tasks[:TASKS_SHOWN],
        available=True,
        closed=answer.closed,
        out_of_service=answer.out_of_service,
    )


class TaskPoller(Poller):
    """Read `url` every `every_s` into `feed` until `stop()`."""

    def __init__(self, url: str, feed: Feed, *, every_s: float = EVERY_S) -> None:
        if not url.startswith(("http://", "https://")):
            raise ValueError(f"tasks URL must be http(s): {url}")
        self.url = url
        self.feed = feed
        super().__init__("vahr-station-tasks", every_s=every_s, join_s=TIMEOUT_S + 1)
        self._warned = False

    def poll(self) -> None:
        """Read once and hand the queue to the feed."""
        try:
            tasks = read_tasks(self.url)
        except (OSError, msgspec.MsgspecError) as err:
            level = logging.DEBUG if self._warned else logging.WARNING
            log.log(level, "cannot read the task queue at %s: %s", self.url, err)
            self._warned = True
            return
        self.feed.set_tasks(tasks)


class _Refusal(msgspec.Struct):
    message: str = "the dispatcher refused"


class ZoneSwitch:
    """Close and open zones at the dispatcher beside `tasks_url` (`POST {api}/vahr/zones/
    {zone}`), then read the queue again so every page shows the change at once."""

    def __init__(self, tasks_url: str, poller: TaskPoller | None = None) -> None:
        self.url = tasks_url.removesuffix("/vahr/tasks") + "/vahr/zones"
        self.poller = poller

    def set(self, zone: str, *, closed: bool) -> dict[str, object]:
        """The dispatcher's answer (`ZoneChange` as JSON); RequestError when it refused."""
        request = urllib.request.Request(
            f"{self.url}/{quote(zone, safe='')}",
            data=msgspec.json.encode({"closed": closed}),
            method="POST",
            # The station records the change in the trail with its operator (controls.py).
            headers={"Content-Type": "application/json", RECORDED_BY_HEADER: "station"},
        )
        try:
            with urllib.request.urlopen(request, timeout=TIMEOUT_S) as answer:  # noqa: S310
                body = answer.read()
        except urllib.error.HTTPError as err:
            try:
                message = msgspec.json.decode(err.read(), type=_Refusal).message
            except msgspec.MsgspecError:
                message = f"the dispatcher answered HTTP {err.code}"
            raise RequestError(400 if err.code < 500 else 503, message) from err
        except OSError as err:
            raise RequestError(503, f"the dispatcher cannot be reached: {err}") from err
        if self.poller is not None:
            self.poller.poll()
        change: dict[str, object] = msgspec.json.decode(body)
        return change
