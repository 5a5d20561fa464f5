"""One robot on a link: decode commands, de-duplicate, execute, and report on the wire.

`RobotAgent` is the glue between the transport (`Link`, `ShadowSync`) and the pure
`Executor`. It subscribes to the robot's command topic, the fleet topic, the fleet's closed
zones (`vahr/fleet/zones`, retained) and its peers' events, turns every payload into a
command or a `rejected` report, and publishes the executor's events
(`vahr/robots/{thing}/events`, `delivered` retained so a peer that starts waiting later
still sees it) and states (the shadow).
"""

from __future__ import annotations

import functools
import json
import logging
from typing import TYPE_CHECKING, Any

from robot_agent.core.executor import Executor
from robot_agent.core.in_flight import INTERRUPTED_REASON, InFlight
from robot_agent.link.shadow import ShadowSync
from vahr.protocol import (
    Presence,
    ProtocolError,
    decode_command,
    decode_event,
    decode_zone_closures,
    encode,
    topics,
)

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.backends.port import NavigationBackend
    from robot_agent.clock import Clock
    from robot_agent.core.executor import ExecutorSettings
    from robot_agent.core.recent_ids import RecentIds
    from robot_agent.voice.port import Voice
    from vahr.domain import Fleet
    from vahr.protocol import Command, Event, Reported
    from vahr.protocol.link import Link

log = logging.getLogger(__name__)

# Events an operator should notice at the default log level and above.
_TROUBLE = frozenset({"rejected", "failed", "stuck"})
_ENDINGS = frozenset({"done", "failed", "cancelled", "rejected"})
# Progress ticks are most of a driving robot's events (a swarm of 10,000 logged thousands a
# second at INFO); the events around them say what the robot did.
_LOG_LEVELS = {"progress": logging.DEBUG}


class RobotAgent:
    """A robot's presence on the broker. Call `attach()` once before the link connects."""

    def __init__(
        self,
        *,
        thing: str,
        fleet: Fleet,
        link: Link,
        backend: NavigationBackend,
        clock: Clock,
        recent_ids: RecentIds,
        voice: Voice | None = None,
        settings: ExecutorSettings | None = None,
        listen_to_peers: bool = True,
        in_flight: InFlight | None = None,
        decode: Callable[[bytes], Command] | None = None,
    ) -> None:
        """`decode` turns a command payload into a command (default: `decode_command` for
        `fleet`); a swarm passes one shared by its robots, which all get each fleet command."""
        self.thing = thing
        self._decode = decode or functools.partial(decode_command, fleet=fleet)
        self.fleet = fleet
        self.link = link
        self.clock = clock
        self.recent_ids = recent_ids
        self.duplicates = 0
        self.shadow = ShadowSync(
            thing=thing, link=link, on_desired_command=self._on_command_payload
        )
        self.executor = Executor(
            thing=thing,
            fleet=fleet,
            backend=backend,
            clock=clock,
            publish_state=self._publish_state,
            publish_event=self._publish_event,
            voice=voice,
            settings=settings,
        )
        self._listen_to_peers = listen_to_peers
        self.in_flight = in_flight or InFlight()
        self._left_over = self.in_flight.left_over()

    def attach(self) -> None:
        """Add this robot's routes and connection callbacks to the link."""
        self.link.add_route(topics.robot_cmd(self.thing), self.on_command)
        self.link.add_route(topics.FLEET_CMD, self.on_command)
        self.link.add_route(topics.FLEET_ZONES, self.on_zone_closures)
        if self._listen_to_peers:
            self.link.add_route(topics.ALL_EVENTS, self.on_peer_event)
        self.link.on_connected(self.on_connected)
        self.link.on_disconnected(self.on_disconnected)

    # -- inbound ------------------------------------------------------------------------

    def on_command(self, topic: str, payload: bytes) -> None:
        self._on_command_payload(payload)

    def _on_command_payload(self, payload: bytes) -> None:
        try:
            command = self._decode(payload)
        except ProtocolError as err:
            command_id, action = _best_effort_identity(payload)
            self.executor.reject(command_id, action, str(err))
            return
        if command.id in self.recent_ids:
            self.duplicates += 1
            log.info("%s: ignored duplicate command %s", self.thing, command.id)
            return
        # Written before the id is saved: a robot killed in between reports it when it is
        # back, or runs its redelivery (see `in_flight`).
        self.in_flight.start(command.id, command.action)
        self.recent_ids.add(command.id)
        log.info(
            "%s: command %s %s from %s", self.thing, command.id, command.action, command.source
        )
        self.executor.execute(command)

    def on_zone_closures(self, topic: str, payload: bytes) -> None:
        """The zones closed now (retained, so also on every connection)."""
        try:
            closures = decode_zone_closures(payload)
        except ProtocolError as err:
            log.warning("%s: ignoring malformed zone closures: %s", self.thing, err)
            return
        self.executor.close_zones(frozenset(closures.closed))

    def on_peer_event(self, topic: str, payload: bytes) -> None:
        # Most events are progress ticks; only deliveries matter, so skip decoding the rest.
        if b'"delivered"' not in payload:
            return
        try:
            event = decode_event(payload)
        except ProtocolError as err:
            log.debug("ignoring a malformed event on %s: %s", topic, err)
            return
        self.executor.peer_event(event)

    def on_connected(self, session_present: bool) -> None:
        self.executor.set_connected(True)
        if self._left_over:
            # Before anything a resumed session redelivers: the sender learns first that
            # the commands the robot died running did not finish. One whose id was never
            # saved was not taken: its redelivery runs (see `in_flight`).
            left_over, self._left_over = self._left_over, []
            self.in_flight.clear()
            for command_id, action in left_over:
                if command_id in self.recent_ids:
                    self.executor.report_interrupted(command_id, action, INTERRUPTED_REASON)
        self.link.publish(
            topics.robot_presence(self.thing),
            encode(Presence(online=True, at=self.clock.now())),
            retain=True,
        )
        self.shadow.report(self.executor.state)
        self.shadow.request_document()

    def on_disconnected(self, reason: str) -> None:
        self.executor.set_connected(False)

    # -- outbound -----------------------------------------------------------------------

    def _publish_state(self, state: Reported) -> None:
        self.shadow.report(state)

    def _publish_event(self, event: Event) -> None:
        self.link.publish(
            topics.robot_events(self.thing), encode(event), retain=event.event == "delivered"
        )
        level = (
            logging.WARNING
            if event.event in _TROUBLE
            else _LOG_LEVELS.get(event.event, logging.INFO)
        )
        # Described only when logged: a swarm publishes thousands of events a second.
        if log.isEnabledFor(level):
            log.log(level, "%s: %s", self.thing, _describe(event))
        # Forgotten only once its end is on record (logged, and queued on the link).
        if event.command_id is not None and event.event in _ENDINGS:
            self.in_flight.end(event.command_id)

    async def shut_down(self) -> None:
        """Cancel the running task, report the final state and presence offline."""
        await self.executor.close()
        self.executor.set_connected(False)
        self.shadow.report(self.executor.state)
        self.link.publish(
            topics.robot_presence(self.thing),
            encode(Presence(online=False, at=self.clock.now())),
            retain=True,
        )


def _best_effort_identity(payload: bytes) -> tuple[str | None, str | None]:
    """The id and action of a rejected payload, when they can be read, for the report."""
    try:
        value: Any = json.loads(payload)
    except (ValueError, RecursionError):  # nested deeper than the parser goes
        return None, None
    if not isinstance(value, dict):
        return None, None
    command_id, action = value.get("id"), value.get("action")
    return (
        command_id if isinstance(command_id, str) and 0 < len(command_id) <= 64 else None,
        action if isinstance(action, str) and len(action) <= 64 else None,
    )


def _describe(event: Event) -> str:
    parts: list[str] = [event.event]
    if event.action:
        parts.append(f"{event.action} {event.command_id}")
    for name in ("zone", "progress", "reason", "text", "intent"):
        value = getattr(event, name)
        if value is not None:
            parts.append(f"{name}={value}")
    return " ".join(parts)
