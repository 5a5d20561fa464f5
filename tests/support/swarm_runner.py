"""The product's swarm (`robot_agent.swarm`, `robot-agent swarm`) for tests and benchmarks.

Its robots are named `{prefix}0001`, `{prefix}0002`, ... on the zones of fleet.yaml
(`swarm_fleet`); `SwarmThread` runs a swarm from synchronous code.

Asynchronous use::

    async with Swarm(broker="mqtt://127.0.0.1:1883", count=100, speed_factor=20) as swarm:
        ...  # swarm.things, swarm.agents[thing].executor.state

From synchronous code (a pytest test, a benchmark), the same on a background thread::

    with SwarmThread(broker="mqtt://127.0.0.1:1883", count=100) as swarm:
        ...  # swarm.things; swarm.state(thing) -> Reported
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from typing import TYPE_CHECKING, Any

from robot_agent.swarm import CONNECT_TIMEOUT_S, STOP_TIMEOUT_S
from robot_agent.swarm import Swarm as ProductSwarm
from vahr.domain import FLEET_GROUP, Fleet, Group, Pose, Robot, load_fleet
from vahr.errors import VahrError
from vahr.navigation import load_floor

if TYPE_CHECKING:
    from vahr.protocol import Reported

__all__ = ["CONNECT_TIMEOUT_S", "STOP_TIMEOUT_S", "Swarm", "SwarmThread", "swarm_fleet"]


def swarm_fleet(count: int, *, prefix: str = "swarm", base: Fleet | None = None) -> Fleet:
    """A fleet of `count` robots `{prefix}0001`.. on the zones of `base` (default fleet.yaml).

    Robots start in a grid of 1 m spacing west of the loading zone, so none starts in a zone;
    on a `base` whose floor is a map, parked on its free ground instead.
    """
    if count < 1:
        raise VahrError("a swarm needs at least one robot")
    base = base or load_fleet()
    width = max(len(str(count)), 4)
    floor = load_floor(base)
    if floor is not None:
        starts = floor.parking(count, spacing=0.6, clear_of_zones=0.8)
    else:
        starts = [
            Pose(-1.0 - (index - 1) // 50, float((index - 1) % 50), 0.0)
            for index in range(1, count + 1)
        ]
    robots = [
        Robot(thing=f"{prefix}{index:0{width}d}", spoken=[f"{prefix} {index}"], start=start)
        for index, start in enumerate(starts, start=1)
    ]
    things = [robot.thing for robot in robots]
    return Fleet(
        robots=robots,
        zones=base.zones,
        groups=[Group(id=FLEET_GROUP, spoken=["all robots"], robots=things)],
        experiment_thing=base.experiment_thing,
        # A drawn floor grows to hold the swarm's grid west of it (every start must lie on
        # it); a map holds the robots parked on it.
        floor=(
            base.floor.covering([robot.start for robot in robots])
            if base.floor and floor is None
            else base.floor
        ),
    ).validate()


class Swarm(ProductSwarm):
    """`count` robots `{prefix}0001`.. of `swarm_fleet` on one link (robot_agent.swarm)."""

    def __init__(
        self, *, count: int, prefix: str = "swarm", base: Fleet | None = None, **arguments: Any
    ) -> None:
        super().__init__(fleet=swarm_fleet(count, prefix=prefix, base=base), **arguments)


class SwarmThread:
    """A `Swarm` on its own event-loop thread, for synchronous callers. Same arguments."""

    def __init__(self, **swarm_arguments: Any) -> None:
        self._arguments = swarm_arguments
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(
            target=self._loop.run_forever, name="vahr-swarm", daemon=True
        )
        self.swarm: Swarm | None = None

    @property
    def things(self) -> list[str]:
        return self.swarm.things if self.swarm else []

    def state(self, thing: str) -> Reported:
        return self._call(self._state(thing))

    async def _state(self, thing: str) -> Reported:
        assert self.swarm is not None
        return self.swarm.state(thing)

    def start(self, timeout_s: float = CONNECT_TIMEOUT_S) -> SwarmThread:
        self._thread.start()
        # Building the robots takes about a second per 5,000 on a busy machine.
        building_s = 5 + int(self._arguments.get("count", 0)) / 500
        try:
            self.swarm = self._call(self._build(), timeout_s + building_s)
            self._call(self.swarm.start(timeout_s), timeout_s + building_s)
        except BaseException:
            self.stop()
            raise
        return self

    async def _build(self) -> Swarm:
        return Swarm(**self._arguments)

    def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> None:
        if self.swarm is not None and self._thread.is_alive():
            with contextlib.suppress(Exception):
                self._call(self.swarm.stop(timeout_s), timeout_s + 5)
        if self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(timeout_s)
        if not self._loop.is_running():
            self._loop.close()

    def _call(self, coroutine: Any, timeout_s: float = 10.0) -> Any:
        return asyncio.run_coroutine_threadsafe(coroutine, self._loop).result(timeout_s)

    def __enter__(self) -> SwarmThread:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
