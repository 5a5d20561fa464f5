"""The audit trail as the station uses it: where the panel's orders are recorded, and the
latest records the pages show.

`StationTrail` is what the station needs of a trail: `append` an entry, and read a
`snapshot` of the records after a number with the trail's head. Three give it:

- `vahr up`'s own trail, handed to its station (the local stack's SQLite trail);
- `HttpTrail`: a running local stack's `/vahr/audit` (`vahr station --api`);
- the DynamoDB audit table on AWS (`vahr station --audit-table`, `skill.audit_table`).

`TrailPoller` reads the newest records every `EVERY_S` on its own thread and hands them to
the feed, which tells the pages when any is new (`Feed.add_records`). A trail that cannot be
read leaves the last records shown, and is logged once.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Protocol

import msgspec

from vahr.errors import VahrError
from vahr.plumbing.client import call
from vahr.protocol import ProtocolError
from vahr.protocol.audit import TrailHead, record_from_builtins
from vahr.station.feed import TRAIL_SHOWN
from vahr.station.polling import Poller

if TYPE_CHECKING:
    from vahr.protocol.audit import AuditEntry, AuditRecord
    from vahr.station.feed import Feed

log = logging.getLogger(__name__)

EVERY_S = 1.0
AUDIT_PATH = "/vahr/audit"
TIMEOUT_S = 3.0


class StationTrail(Protocol):
    def append(self, entry: AuditEntry) -> object:
        """Record `entry`; raises VahrError (or the trail's own error) when it cannot."""
        ...

    def snapshot(self, after: int, limit: int) -> tuple[list[AuditRecord], TrailHead | None]:
        """Up to `limit` records numbered above `after`, and the trail's head."""
        ...


class HttpTrail:
    """A running local stack's trail, over its data plane."""

    def __init__(self, api_url: str) -> None:
        self.api_url = api_url.rstrip("/")

    def append(self, entry: AuditEntry) -> object:
        return call(
            self.api_url, "POST", AUDIT_PATH, msgspec.to_builtins(entry), timeout_s=TIMEOUT_S
        )

    def snapshot(self, after: int, limit: int) -> tuple[list[AuditRecord], TrailHead | None]:
        page = call(
            self.api_url, "GET", f"{AUDIT_PATH}?after={after}&limit={limit}", timeout_s=TIMEOUT_S
        )
        try:
            records = [record_from_builtins(item) for item in page.get("records", [])]
        except ProtocolError as err:
            raise VahrError(f"{self.api_url}{AUDIT_PATH}: {err}") from err
        head = page.get("head")
        return records, (TrailHead(int(head["seq"]), str(head["hash"])) if head else None)


class TrailPoller(Poller):
    """Read the trail's newest records into `feed` every `every_s` until `stop()`."""

    def __init__(self, trail: StationTrail, feed: Feed, *, every_s: float = EVERY_S) -> None:
        self.trail = trail
        self.feed = feed
        self._after: int | None = None
        super().__init__("vahr-station-trail", every_s=every_s, join_s=TIMEOUT_S + 1)
        self._warned = False

    def poll(self) -> None:
        """Read what is new (at first, the latest `TRAIL_SHOWN`) and hand it to the feed."""
        try:
            if self._after is None:
                _, head = self.trail.snapshot(0, 1)
                self._after = max(0, (head.seq if head else 0) - TRAIL_SHOWN)
            records, _ = self.trail.snapshot(self._after, TRAIL_SHOWN)
        except Exception as err:  # noqa: BLE001 - any trail's failure: shown as before, logged
            level = logging.DEBUG if self._warned else logging.WARNING
            log.log(level, "cannot read the audit trail: %s", err)
            self._warned = True
            return
        if records:
            self._after = records[-1].seq
        self.feed.add_records(records)
