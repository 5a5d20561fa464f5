"""Fixtures for the executor's tests: a fast simulated robot and a recorder of what it says."""

from __future__ import annotations

import asyncio
import inspect
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import pytest

from robot_agent.backends.sim import SimBackend
from robot_agent.clock import ScaledClock
from robot_agent.config import ExecutorSettings, SimSettings
from robot_agent.core.executor import Executor

if TYPE_CHECKING:
    from robot_agent.backends.sim_ticker import SimTicker
    from robot_agent.voice.port import Voice
    from vahr.domain import Fleet
    from vahr.navigation import FleetFloor
    from vahr.protocol import Event, Reported


# The longest any `async def` test may run, so that a task which never ends fails the test.
ASYNC_TEST_TIMEOUT_S = 60.0


@pytest.hookimpl(tryfirst=True)
def pytest_pyfunc_call(pyfuncitem: pytest.Function) -> bool | None:
    """Run `async def` tests in a fresh event loop (no asyncio plugin is pinned)."""
    if not inspect.iscoroutinefunction(pyfuncitem.obj):
        return None
    names = pyfuncitem._fixtureinfo.argnames
    test = pyfuncitem.obj(**{name: pyfuncitem.funcargs[name] for name in names})
    asyncio.run(asyncio.wait_for(test, ASYNC_TEST_TIMEOUT_S))
    return True


# Simulated time runs this much faster than the wall clock in these tests.
SPEED = 400.0


@dataclass
class Recorder:
    """Everything the executor published, in order."""

    states: list[Reported] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)

    def kinds(self, command_id: str | None = None) -> list[str]:
        return [e.event for e in self.events if command_id is None or e.command_id == command_id]

    def first(self, kind: str, command_id: str | None = None) -> Event:
        return next(
            e
            for e in self.events
            if e.event == kind and (command_id is None or e.command_id == command_id)
        )

    async def until(
        self, kind: str, command_id: str | None = None, timeout_s: float = 5.0
    ) -> Event:
        async with asyncio.timeout(timeout_s):
            while True:
                for event in self.events:
                    if event.event == kind and (
                        command_id is None or event.command_id == command_id
                    ):
                        return event
                await asyncio.sleep(0.002)


async def until_moved(backend: SimBackend, timeout_s: float = 5.0) -> None:
    """Wait until the robot has left where it stood: it is driving, whatever its reporting
    rate (progress events may be seconds apart, or none on a short drive)."""
    start = backend.pose
    async with asyncio.timeout(timeout_s):
        while backend.pose.distance_to(start) < 0.05:
            await asyncio.sleep(0.002)


def make_executor(
    fleet: Fleet,
    *,
    thing: str = "placebot1",
    voice: Voice | None = None,
    sim: SimSettings | None = None,
    settings: ExecutorSettings | None = None,
    speed: float = SPEED,
    clock: ScaledClock | None = None,
    ticker: SimTicker | None = None,
    floor: FleetFloor | None = None,
) -> tuple[Executor, Recorder, SimBackend]:
    """A robot's executor on the simulator; robots given one `clock` and `ticker` share them
    (as a swarm's do); with `floor`, it plans its paths on that map."""
    clock = clock or ScaledClock(speed)
    backend = SimBackend(
        start=fleet.robot(thing).start, clock=clock, settings=sim, ticker=ticker, floor=floor
    )
    recorder = Recorder()
    executor = Executor(
        thing=thing,
        fleet=fleet,
        backend=backend,
        clock=clock,
        publish_state=recorder.states.append,
        publish_event=recorder.events.append,
        voice=voice,
        # Generous stuck time: at this speed 10 simulated seconds are 25 ms of a busy machine.
        settings=settings or ExecutorSettings(stuck_after_s=120),
    )
    return executor, recorder, backend


@pytest.fixture
def robot(fleet: Fleet) -> tuple[Executor, Recorder, SimBackend]:
    return make_executor(fleet)
