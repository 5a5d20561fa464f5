"""Injected time: the executor and the simulator never call `time` or `asyncio.sleep` directly.

It sits beside the core rather than in it: the simulator backend keeps time too, and a
backend never imports the core that drives it.

A `ScaledClock` runs simulated time `speed_factor` times faster than the wall clock, so a
30-second delivery takes 0.3 s in a test with a factor of 100. Timestamps on the wire stay
wall-clock UTC (`now`), since peers and the skill compare them with their own clocks.
"""

from __future__ import annotations

import asyncio
import time
from datetime import UTC, datetime
from typing import Protocol


class Clock(Protocol):
    def monotonic(self) -> float:
        """Simulated seconds since an arbitrary origin; never goes backwards."""

    async def sleep(self, seconds: float) -> None:
        """Wait `seconds` of simulated time."""

    def now(self) -> datetime:
        """Wall-clock UTC time for timestamps on the wire."""


class ScaledClock:
    """Simulated time running `speed_factor` times faster than the wall clock (1 = real time)."""

    def __init__(self, speed_factor: float = 1.0) -> None:
        if speed_factor <= 0:
            raise ValueError("speed_factor: must be greater than 0")
        self.speed_factor = speed_factor
        self._origin = time.monotonic()

    def monotonic(self) -> float:
        return (time.monotonic() - self._origin) * self.speed_factor

    async def sleep(self, seconds: float) -> None:
        await asyncio.sleep(max(0.0, seconds) / self.speed_factor)

    def now(self) -> datetime:
        return datetime.now(UTC)

    def to_wall_seconds(self, seconds: float) -> float:
        """How long `seconds` of simulated time lasts on the wall clock."""
        return seconds / self.speed_factor
