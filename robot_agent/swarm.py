"""Swarm mode: many simulated robots in one process, on one event loop and one MQTT link.

For fleets larger than one process per robot allows (`robot-agent swarm`, which `vahr up
--swarm N` starts), and for fan-out tests and benchmarks. Each robot is a full
`RobotAgent` (executor, simulator, shadow sync) of the fleet it is given; it listens on its
own command topic and on the fleet topic, reports in its classic shadow and publishes its
events, exactly like a robot run by `robot-agent run`. They share one connection, so there
is no per-robot last will: `stop()` publishes every robot's offline presence itself, and a
swarm killed outright leaves its robots' presence online until it starts again.

The shared connection must be allowed to speak for every robot: a plaintext loopback
broker, or the local stack's mTLS listener with the service identity.

    async with Swarm(fleet=fleet, broker="mqtt://127.0.0.1:1883", speed_factor=20) as swarm:
        ...  # swarm.things, swarm.agents[thing].executor.state
"""

from __future__ import annotations

import asyncio
import uuid
from typing import TYPE_CHECKING, Any

from robot_agent.agent import RobotAgent
from robot_agent.assembly import robot_floor
from robot_agent.backends.sim import SimBackend
from robot_agent.backends.sim_battery import BatteryTicker
from robot_agent.backends.sim_ticker import SimTicker
from robot_agent.clock import ScaledClock
from robot_agent.config import ExecutorSettings, MqttSettings, SimSettings
from robot_agent.core.recent_ids import RecentIds
from robot_agent.dev_faults import DevFaults
from vahr.errors import VahrError
from vahr.protocol import ProtocolError, decode_command, decode_event, topics

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from pathlib import Path
    from types import TracebackType

    from robot_agent.link.mqtt5 import Mqtt5Link
    from vahr.domain import Fleet
    from vahr.protocol import Command, Event, Reported
    from vahr.protocol.broker import ClientCredentials

CONNECT_TIMEOUT_S = 10.0
STOP_TIMEOUT_S = 10.0


class Swarm:
    """The robots `things` of `fleet` (default: all of them) on one link."""

    def __init__(
        self,
        *,
        fleet: Fleet,
        broker: str,
        things: Sequence[str] | None = None,
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
        event log); with `tls`, `broker` is an `mqtts://` listener and the link holds that
        identity. `sim.accept_faults` attaches `vahr fault`'s route to every robot."""
        self.broker = broker
        self._listen_to_peers = listen_to_peers
        self.fleet = fleet
        self.things = list(fleet.robot_things if things is None else things)
        unknown = sorted(set(self.things) - set(fleet.robot_things))
        if unknown:
            raise VahrError(f"not robots of the fleet: {', '.join(unknown[:5])}")
        if not self.things:
            raise VahrError("a swarm needs at least one robot")
        self.clock = ScaledClock(speed_factor)
        self._sim = sim or SimSettings()
        # One timer steps every robot's drive: one per robot cost more than the motion.
        self.ticker = SimTicker(clock=self.clock, tick_s=self._sim.tick_s)
        # And one settles every robot's battery while it stands.
        self.battery_ticker = BatteryTicker(clock=self.clock)
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
        from robot_agent.link.mqtt5 import LinkSettings, Mqtt5Link
        from vahr.protocol.broker import parse_broker_url, plaintext_loopback

        if self._tls is None:
            address = plaintext_loopback(self.broker)
        else:
            address = parse_broker_url(self.broker)
        link = Mqtt5Link(
            LinkSettings(
                client_id=self._client_id,
                host=address.host,
                port=address.port,
                tls=self._tls,
                session=MqttSettings(session_expiry_s=self._session_expiry_s),
            ),
            asyncio.get_running_loop(),
        )
        self.link = link
        # Looked up once: Fleet.robot is a linear search, quadratic over 10,000 robots.
        starts = {robot.thing: robot.start for robot in self.fleet.robots}
        decode = _DecodedOnce(self.fleet)
        # One map and its searches serve every robot (a goal's field is computed once).
        floor = robot_floor(self.fleet)
        for thing in self.things:
            recent = RecentIds(
                self._state_dir / thing / "recent-ids.json" if self._state_dir else None
            )
            backend = SimBackend(
                start=starts[thing],
                clock=self.clock,
                settings=self._sim,
                ticker=self.ticker,
                floor=floor,
                battery=self.fleet.battery_rates(thing),
                chargers=self.fleet.chargers,
                battery_ticker=self.battery_ticker,
            )
            agent = _LoggedAgent(
                self._on_event,
                self._tell_peers if self._listen_to_peers else None,
                thing=thing,
                fleet=self.fleet,
                link=link,
                backend=backend,
                clock=self.clock,
                recent_ids=recent,
                settings=self._settings,
                # One shared route decodes each peer event once for every robot.
                listen_to_peers=False,
                decode=decode,
            )
            agent.attach()
            backend.watch_battery(agent.executor.report_battery)
            if self._sim.accept_faults:
                DevFaults(thing=thing, link=link, backend=backend).attach()
            self.agents[thing] = agent
        if self._listen_to_peers:
            # Only robots outside this process: the broker would send back every event this
            # swarm publishes (most of its traffic, mostly progress), and its own robots'
            # deliveries reach their peers here directly (`_LoggedAgent`).
            link.add_route(topics.ALL_EVENTS, self._on_peer_event, no_local=True)
        await link.start(timeout_s)

    def _on_peer_event(self, topic: str, payload: bytes) -> None:
        if b'"delivered"' not in payload:
            return
        try:
            event = decode_event(payload)
        except ProtocolError:
            return
        self._tell_peers(event)

    def _tell_peers(self, event: Event) -> None:
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


class _DecodedOnce:
    """Decodes command payloads for every robot of a swarm: a fleet command reaches each
    of them with the same bytes, one after another, and is decoded (and validated) once.
    Commands are frozen, so the robots can share one."""

    def __init__(self, fleet: Fleet) -> None:
        self._fleet = fleet
        self._payload: bytes | None = None
        self._outcome: Command | ProtocolError | None = None

    def __call__(self, payload: bytes) -> Command:
        if payload != self._payload or self._outcome is None:
            try:
                self._outcome = decode_command(payload, self._fleet)
            except ProtocolError as err:
                self._outcome = err
            self._payload = payload
        if isinstance(self._outcome, ProtocolError):
            # Without its last traceback: raised for every robot, it would grow one.
            raise self._outcome.with_traceback(None)
        return self._outcome


class _LoggedAgent(RobotAgent):
    """A robot whose every published event is also handed to `on_event`, and whose
    deliveries are told to `tell_peers` (the other robots of its swarm)."""

    def __init__(
        self,
        on_event: Callable[[Event], None] | None,
        tell_peers: Callable[[Event], None] | None,
        **arguments: Any,
    ) -> None:
        super().__init__(**arguments)
        self._on_event = on_event
        self._tell_peers = tell_peers

    def _publish_event(self, event: Event) -> None:
        super()._publish_event(event)
        if self._tell_peers is not None and event.event == "delivered":
            self._tell_peers(event)
        if self._on_event is not None:
            self._on_event(event)
