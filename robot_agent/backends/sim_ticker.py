"""One timer that steps the drives of every simulated robot on an event loop.

A `SimBackend` driving to a zone hands its drive to a `SimTicker` instead of sleeping one
tick at a time on a timer of its own: with 10,000 robots in one process (swarm mode), 10,000
timers firing every tick cost more than the motion they simulate, and the process fell
behind until robots looked stuck. The ticker wakes once per tick of simulated time and
steps every drive in turn, each over the simulated time that really passed since its last
step, so a busy process changes how often poses are updated, never how fast robots move.

It never takes the loop for long: drives are stepped in chunks with a yield between them
(commands and acknowledgments get through during a step), and after a step that took `S`
wall seconds it rests at least `S` before the next one, so at worst it takes half the
loop's time and the robots' poses are updated less often.
"""

from __future__ import annotations

import asyncio
import logging
import time
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from robot_agent.clock import Clock

log = logging.getLogger(__name__)

# Drives stepped between two yields to the event loop.
CHUNK = 250


class Drive(Protocol):
    """One robot's motion towards a goal, as the ticker steps it."""

    def step(self, now: float) -> bool:
        """Advance to simulated time `now`; True when the drive has ended (arrived or
        failed: the drive settles its own waiter)."""

    def crash(self, error: BaseException) -> None:
        """`step` raised `error`: end the drive with it."""


class SimTicker:
    """Steps every registered `Drive` once per `tick_s` of the clock's simulated time."""

    def __init__(self, *, clock: Clock, tick_s: float) -> None:
        self._clock = clock
        self._tick_s = tick_s
        # Insertion-ordered, so drives are stepped in the order they started.
        self._drives: dict[Drive, None] = {}
        self._task: asyncio.Task[None] | None = None
        self.steps = 0

    def add(self, drive: Drive) -> None:
        self._drives[drive] = None
        if self._task is None or self._task.done():
            self._task = asyncio.get_running_loop().create_task(self._run(), name="sim-ticker")

    def discard(self, drive: Drive) -> None:
        self._drives.pop(drive, None)
        if not self._drives and self._task is not None:
            # Nothing left to step: stop now rather than a tick later, so that a robot
            # shutting down leaves no task of the ticker's behind on its event loop.
            self._task.cancel()
            self._task = None

    @property
    def driving(self) -> int:
        return len(self._drives)

    async def _run(self) -> None:
        busy_s = 0.0
        while self._drives:
            await self._clock.sleep(self._tick_s)
            # Rest at least as long as the last step took (see the module docstring).
            if busy_s > self._wall(self._tick_s):
                await asyncio.sleep(busy_s - self._wall(self._tick_s))
            now = self._clock.monotonic()
            drives = list(self._drives)
            busy_s = 0.0
            for start in range(0, len(drives), CHUNK):
                began = time.perf_counter()
                for drive in drives[start : start + CHUNK]:
                    if drive in self._drives:  # else it ended while an earlier chunk ran
                        self._step(drive, now)
                busy_s += time.perf_counter() - began
                if start + CHUNK < len(drives):
                    await asyncio.sleep(0)
            self.steps += 1

    def _step(self, drive: Drive, now: float) -> None:
        try:
            ended = drive.step(now)
        except Exception as err:  # one robot's failure must not stop the others
            self._drives.pop(drive, None)
            drive.crash(err)
            return
        if ended:
            self._drives.pop(drive, None)

    def _wall(self, seconds: float) -> float:
        to_wall = getattr(self._clock, "to_wall_seconds", None)
        return float(to_wall(seconds)) if callable(to_wall) else seconds
