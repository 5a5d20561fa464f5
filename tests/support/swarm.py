"""Swarm mode: many simulated robots in one process, on one event loop and one MQTT link.

For fan-out tests and benchmarks of the local stack. Each robot is a full `RobotAgent`
(executor, simulator, shadow sync) named `{prefix}0001`, `{prefix}0002`, ...; it listens
on its own command topic and on the fleet topic, reports in its classic shadow
(`$aws/things/{thing}/shadow/update`) and publishes its events, exactly like a robot run
by `robot-agent run`. They share one plaintext connection to a loopback broker, so there is
no per-robot last will: `stop()` publishes every robot's offline presence itself.

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
import uuid
from typing import TYPE_CHECKING, Any

from robot_agent.agent import RobotAgent
from robot_agent.backends.sim import SimBackend
from robot_agent.clock import ScaledClock
from robot_agent.config import ExecutorSettings, SimSettings
from robot_agent.core.recent_ids import RecentIds
from vahr.errors import VahrError
from vahr.protocol import (
    FLEET_GROUP,
    Fleet,
    Group,
    Pose,
    ProtocolError,
    Robot,
    decode_event,
    load_fleet,
    topics,
)

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path
    from types import TracebackType

    from robot_agent.link.mqtt5 import Mqtt5Link
    from vahr.protocol import Event, Reported
    from vahr.protocol.broker import ClientCredentials

CONNECT_TIMEOUT_S = 10.0
STOP_TIMEOUT_S = 10.0


def swarm_fleet(count: int, *, prefix: str = "swarm", base: Fleet | None = None) -> Fleet:
    """A fleet of `count` robots `{prefix}0001`.. on the zones of `base` (default fleet.yaml).

    Robots start in a grid of 1 m spacing west of the loading zone, so none starts in a zone.
    """
    if count < 1:
        raise VahrError("a swarm needs at least one robot")
    base = base or load_fleet()
    width = max(len(str(count)), 4)
    robots = [
        Robot(
            thing=f"{prefix}{index:0{width}d}",
            spoken=[f"{prefix} {index}"],
            start=Pose(-1.0 - (index - 1) // 50, float((index - 1) % 50), 0.0),
        )
        for index in range(1, count + 1)
    ]
    things = [robot.thing for robot in robots]
    return Fleet(
        robots=robots,
        zones=base.zones,
        groups=[Group(id=FLEET_GROUP, spoken=["all robots"], robots=things)],
        experiment_thing=base.experiment_thing,
        # The floor grows to hold the swarm's grid west of it (every start must lie on it).
        floor=base.floor.covering([robot.start for robot in robots]) if base.floor else None,
    ).validate()


class Swarm:
    """`count` simulated robots on one link; see the module docstring."""

    def __init__(
        self,
        *,
        broker: str,
        count: int,
        prefix: str = "swarm",
        speed_factor: float = 1.0,
        sim: SimSettings | None = None,
        settings: ExecutorSettings | None = None,
        state_dir: Path | None = None,
        client_id: str | None = None,
        listen_to_peers: bool = True,
        session_expiry_s: int = 0,
        on_event: Callable[[Event], None] | None = None,
        tls: ClientCredentials | None = None,
    ) -> None:
        """`listen_to_peers=False` leaves out the route on every robot's events, which only
        sequential deliveries need (a fan-out benchmark would otherwise receive each of its
        robots' events back). `session_expiry_s` > 0 makes the link's session persistent
        (with a fixed `client_id`, the broker queues QoS 1 commands while the link is down);
        `on_event` sees every event any robot publishes, as the robot publishes it (its
        event log); with `tls`, `broker` is the local stack's `mqtts://` listener and the
        link holds that identity (the service's, to speak for every robot)."""
        self.broker = broker
        self._listen_to_peers = listen_to_peers
        self.fleet = swarm_fleet(count, prefix=prefix)
        self.things = list(self.fleet.robot_things)
        self.clock = ScaledClock(speed_factor)
        self._sim = sim or SimSettings()
        self._settings = settings or ExecutorSettings()
        self._state_dir = state_dir
        self._client_id = client_id or f"vahr-swarm-{uuid.uuid4().hex[:8]}"
        self._session_expiry_s = session_expiry_s
        self._on_event = on_event
        self._tls = tls
        self.agents: dict[str, RobotAgent] = {}
        self.link: Mqtt5Link | None = None

    async def start(self, timeout_s: float = CONNECT_TIMEOUT_S) -> None:
        """Build every robot, connect once, and return when all of them are online."""
        from robot_agent.config import MqttSettings
        from robot_agent.link.mqtt5 import LinkSettings, Mqtt5Link
        from vahr.protocol.broker import parse_broker_url, plaintext_loopback

        if self._tls is None:
            address = plaintext_loopback(self.broker)
        else:
            address = parse_broker_url(self.broker)
        host, port = address.host, address.port
        link = Mqtt5Link(
            LinkSettings(
                client_id=self._client_id,
                host=host,
                port=port,
                tls=self._tls,
                session=MqttSettings(session_expiry_s=self._session_expiry_s),
            ),
            asyncio.get_running_loop(),
        )
        self.link = link
        # Looked up once: Fleet.robot is a linear search, quadratic over 10,000 robots.
        starts = {robot.thing: robot.start for robot in self.fleet.robots}
        for thing in self.things:
            recent = RecentIds(
                self._state_dir / thing / "recent-ids.json" if self._state_dir else None
            )
            agent = _LoggedAgent(
                self._on_event,
                thing=thing,
                fleet=self.fleet,
                link=link,
                backend=SimBackend(start=starts[thing], clock=self.clock, settings=self._sim),
                clock=self.clock,
                recent_ids=recent,
                settings=self._settings,
                # One shared route decodes each peer event once for every robot.
                listen_to_peers=False,
            )
            agent.attach()
            self.agents[thing] = agent
        if self._listen_to_peers:
            link.add_route(topics.ALL_EVENTS, self._on_peer_event)
        await link.start(timeout_s)

    def _on_peer_event(self, topic: str, payload: bytes) -> None:
        if b'"delivered"' not in payload:
            return
        try:
            event = decode_event(payload)
        except ProtocolError:
            return
        for agent in self.agents.values():
            agent.executor.peer_event(event)

    def state(self, thing: str) -> Reported:
        return self.agents[thing].executor.state

    async def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> None:
        """Cancel running tasks, report final states and offline presence, disconnect."""
        if self.link is None:
            return
        await asyncio.gather(*(agent.shut_down() for agent in self.agents.values()))
        await self.link.flush(timeout_s)
        await self.link.stop(timeout_s)
        self.link = None

    async def __aenter__(self) -> Swarm:
        try:
            await self.start()
        except BaseException:
            await self.stop()
            raise
        return self

    async def __aexit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        await self.stop()


class _LoggedAgent(RobotAgent):
    """A robot whose every published event is also handed to `on_event`."""

    def __init__(self, on_event: Callable[[Event], None] | None, **arguments: Any) -> None:
        super().__init__(**arguments)
        self._on_event = on_event

    def _publish_event(self, event: Event) -> None:
        super()._publish_event(event)
        if self._on_event is not None:
            self._on_event(event)


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
