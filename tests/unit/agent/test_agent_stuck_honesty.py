"""Stuck detection is about the robot, not the process: a simulated robot that drives is
never called stuck because its process was too busy to step it, and one that really stands
still is called stuck on time, busy process or not."""

from __future__ import annotations

import asyncio
import contextlib
import time
from typing import TYPE_CHECKING

from robot_agent.backends.sim_ticker import SimTicker
from robot_agent.clock import ScaledClock
from robot_agent.config import ExecutorSettings, SimSettings
from tests.unit.agent.conftest import SPEED, make_executor, until_moved
from vahr.protocol import new_command

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.domain import Fleet

STUCK_AFTER_S = 5.0


@contextlib.contextmanager
def busy_loop(block_s: float) -> Iterator[None]:
    """Every turn of the event loop takes `block_s` more wall seconds, as when thousands of
    robots' callbacks share it."""
    loop = asyncio.get_running_loop()
    running = True

    def hog() -> None:
        if running:
            time.sleep(block_s)
            loop.call_soon(hog)

    loop.call_soon(hog)
    try:
        yield
    finally:
        running = False


def navigate(zone: str, command_id: str):  # type: ignore[no-untyped-def]
    return new_command("navigate", {"zone": zone}, source="console", command_id=command_id)


async def test_driving_robots_in_a_starved_process_arrive_and_none_is_stuck(
    fleet: Fleet,
) -> None:
    # Given 100 robots in one process that call 5 simulated seconds without progress stuck
    robots = [
        make_executor(fleet, settings=ExecutorSettings(stuck_after_s=STUCK_AFTER_S))
        for _ in range(100)
    ]
    # and a process where every turn of the event loop lasts 0.6 of that time, as when
    # thousands of robots share it
    with busy_loop(0.6 * STUCK_AFTER_S / SPEED):
        # When they all drive to D
        for index, (executor, _, _) in enumerate(robots):
            executor.execute(navigate("D", f"n{index}"))
        for executor, _, _ in robots:
            await executor.wait_idle()
    # Then every one arrived, and none said it was stuck
    for index, (_, rec, _) in enumerate(robots):
        assert rec.kinds(f"n{index}")[-2:] == ["arrived", "done"]
        assert rec.states[-1].zone == "D"


async def test_a_robot_stuck_by_an_injected_fault_is_stuck_in_a_starved_process_too(
    fleet: Fleet,
) -> None:
    # Given a robot in a process as starved as above, blocked by a fault on its next goal
    # (`vahr fault THING stuck`: it stops half way)
    executor, rec, backend = make_executor(
        fleet, settings=ExecutorSettings(stuck_after_s=STUCK_AFTER_S)
    )
    backend.inject_stuck()
    with busy_loop(0.6 * STUCK_AFTER_S / SPEED):
        # When it drives to D
        executor.execute(navigate("D", "n2"))
        await executor.wait_idle()
    # Then it reports stuck with the reason, short of D, and the task failed
    stuck = rec.first("stuck", "n2")
    assert stuck.reason == "no progress towards D for 5 s"
    assert stuck.pose is not None
    assert backend.pose.distance_to(fleet.zone("D").pose) > fleet.zone("D").radius
    assert rec.kinds("n2")[-1] == "failed"
    assert rec.states[-1].status == "stuck"


async def test_a_stuck_robot_is_stuck_after_the_simulated_time_not_before(fleet: Fleet) -> None:
    # Given a robot whose goal to D sticks half way, at 20 times real time
    speed = 20.0
    executor, rec, backend = make_executor(
        fleet,
        sim=SimSettings(stuck_zones=("D",)),
        settings=ExecutorSettings(stuck_after_s=STUCK_AFTER_S),
        speed=speed,
    )
    executor.execute(navigate("D", "n3"))
    await until_moved(backend)
    # When it has stopped moving (two samples a simulated half second apart agree)
    async with asyncio.timeout(10):
        before, still_since = backend.pose, time.monotonic()
        while True:
            await asyncio.sleep(0.5 / speed)
            if backend.pose == before:
                break
            before, still_since = backend.pose, time.monotonic()
    await rec.until("stuck", "n3", timeout_s=10)
    waited_s = (time.monotonic() - still_since) * speed
    # Then stuck came once 5 simulated seconds without progress had passed, not at the
    # first still step (the upper bound allows a busy machine's delay)
    assert STUCK_AFTER_S - 1.0 <= waited_s <= STUCK_AFTER_S + 4.0


async def test_robots_sharing_a_ticker_are_stepped_by_one_timer(fleet: Fleet) -> None:
    # Given two robots on one event loop with one ticker
    clock = ScaledClock(SPEED)
    ticker = SimTicker(clock=clock, tick_s=SimSettings().tick_s)
    executors, recorders = [], []
    for thing in ("placebot1", "placebot2"):
        executor, recorder, _ = make_executor(
            fleet,
            thing=thing,
            clock=clock,
            ticker=ticker,
            settings=ExecutorSettings(stuck_after_s=STUCK_AFTER_S),
        )
        executors.append(executor)
        recorders.append(recorder)
    # When both drive at once
    executors[0].execute(navigate("A", "t1"))
    executors[1].execute(navigate("C", "t2"))
    while ticker.driving < 2:
        await asyncio.sleep(0.001)
    # Then one task steps both, and each arrives where it was sent
    tickers = [t for t in asyncio.all_tasks() if t.get_name() == "sim-ticker"]
    assert len(tickers) == 1
    for executor in executors:
        await executor.wait_idle()
    assert [r.states[-1].zone for r in recorders] == ["A", "C"]
    assert ticker.driving == 0
