"""What the robot knows of its peers' deliveries, for `sequential_delivery`.

A peer's `delivered` event may arrive before the wait begins (the peer was faster, this
robot received its command late, or the event is the retained one on its events topic), so
deliveries are remembered. Only a delivery made after the command was issued counts: an
older one belongs to an earlier task and must not release a new sequence. `skew_s`
tolerates clocks (the peer's and the sender's) that disagree by that much.
"""

from __future__ import annotations

import asyncio
from datetime import timedelta
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from datetime import datetime


class PeerDeliveries:
    """The latest `delivered` time of each peer, and waiters for the next one."""

    def __init__(self) -> None:
        self._latest: dict[str, datetime] = {}
        self._waiters: dict[str, list[asyncio.Future[datetime]]] = {}

    def record(self, thing: str, at: datetime) -> None:
        previous = self._latest.get(thing)
        if previous is None or at > previous:
            self._latest[thing] = at
        for waiter in self._waiters.pop(thing, []):
            if not waiter.done():
                waiter.set_result(at)

    def latest(self, thing: str) -> datetime | None:
        return self._latest.get(thing)

    def delivered_since(self, thing: str, since: datetime, skew_s: float) -> datetime | None:
        """The peer's delivery time if it is at or after `since - skew_s`, else None."""
        at = self._latest.get(thing)
        if at is not None and at >= since - timedelta(seconds=skew_s):
            return at
        return None

    def next_delivery(self, thing: str) -> asyncio.Future[datetime]:
        """A future resolved by the peer's next recorded delivery."""
        future: asyncio.Future[datetime] = asyncio.get_running_loop().create_future()
        self._waiters.setdefault(thing, []).append(future)
        return future
