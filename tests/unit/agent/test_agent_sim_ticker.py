"""The simulator's ticker: one timer for every drive, which shares the event loop."""

from __future__ import annotations

import asyncio
import time

import pytest

from robot_agent.backends.sim_ticker import CHUNK, SimTicker
from robot_agent.clock import ScaledClock

TICK_S = 0.25


class CountedDrive:
    """A drive that ends after `steps` steps, each taking `cost_s` of CPU."""

    def __init__(self, steps: int, cost_s: float = 0.0) -> None:
        self.left = steps
        self.cost_s = cost_s
        self.times: list[float] = []
        self.ended = asyncio.get_running_loop().create_future()

    def step(self, now: float) -> bool:
        self.times.append(now)
        if self.cost_s:
            until = time.perf_counter() + self.cost_s
            while time.perf_counter() < until:
                pass
        self.left -= 1
        if self.left == 0:
            self.ended.set_result(None)
            return True
        return False

    def crash(self, error: BaseException) -> None:
        self.ended.set_exception(error)


class BrokenDrive(CountedDrive):
    def step(self, now: float) -> bool:
        raise ValueError("a bug in one robot")


async def test_other_work_runs_between_chunks_of_a_large_step() -> None:
    # Given a ticker with three chunks' worth of drives, each step costing a little CPU
    ticker = SimTicker(clock=ScaledClock(50), tick_s=TICK_S)
    drives = [CountedDrive(steps=2, cost_s=0.0001) for _ in range(3 * CHUNK)]
    for drive in drives:
        ticker.add(drive)
    # When other work on the loop notes how many drives had been stepped each turn
    loop = asyncio.get_running_loop()
    seen: list[int] = []
    running = True

    def other_work() -> None:
        if running:
            seen.append(sum(len(d.times) for d in drives))
            loop.call_soon(other_work)

    loop.call_soon(other_work)
    await asyncio.wait_for(asyncio.gather(*(d.ended for d in drives)), 10)
    running = False
    # Then every drive took its two steps, at one simulated time per step for all
    assert all(len(d.times) == 2 for d in drives)
    assert len({d.times[0] for d in drives}) == 1
    # and the loop turned while the first step was part way through the drives
    assert any(0 < count < len(drives) for count in seen)
    assert ticker.driving == 0


async def test_a_drive_that_raises_ends_alone_and_the_others_go_on() -> None:
    # Given two drives on one ticker, one of which has a bug
    ticker = SimTicker(clock=ScaledClock(50), tick_s=TICK_S)
    broken, healthy = BrokenDrive(steps=1), CountedDrive(steps=3)
    ticker.add(broken)
    ticker.add(healthy)
    # Then the broken one ends with its error and the other drives to its end
    await asyncio.wait_for(healthy.ended, 5)
    with pytest.raises(ValueError, match="a bug in one robot"):
        await broken.ended
    assert len(healthy.times) == 3
    assert ticker.driving == 0
