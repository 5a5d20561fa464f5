"""The skill's view of the robots: send commands and confirm them, read their shadows.

It sits between the handlers and the RobotGateway port: the handlers say what to send, this
module publishes it, waits for the acknowledgments and reads shadows concurrently.
"""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING

import msgspec

from skill import deeds
from skill.acknowledgment import MAX_WORKERS, await_acknowledgments
from skill.errors import GatewayError
from skill.logs import log_event
from vahr.protocol import ProtocolError, encode, robot_shadow_from_payload

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from skill.acknowledgment import RobotAnswer
    from skill.commands import Publication
    from skill.fleet_acknowledgment import FleetAcknowledgments
    from skill.gateway import RobotGateway
    from vahr.protocol import RobotShadow


class ShadowRead(msgspec.Struct, frozen=True):
    """A robot's shadow (None if it has none yet), or the error that kept it from being read."""

    thing: str
    shadow: RobotShadow | None = None
    error: str | None = None


# Everything one command takes (publishing and waiting), so the answer reaches Alexa well
# inside its 8 s even when a slow publish ate into the acknowledgment budget.
REPLY_BUDGET_S = 6.0


class Robots:
    """Publishes commands, awaits acknowledgments, and reads shadows through a gateway."""

    def __init__(
        self,
        gateway: RobotGateway,
        ack_timeout_s: float,
        *,
        reply_budget_s: float = REPLY_BUDGET_S,
        clock: Callable[[], float] = time.monotonic,
        many: FleetAcknowledgments | None = None,
    ) -> None:
        """`many` counts the acknowledgments of one command to many robots with the fleet
        index (skill.fleet_acknowledgment): their shadows cannot all be read in time."""
        self.gateway = gateway
        self.ack_timeout_s = ack_timeout_s
        self.reply_budget_s = reply_budget_s
        self._clock = clock
        self._many = many

    def send(self, publications: Sequence[Publication]) -> dict[str, RobotAnswer]:
        """Publish every dispatch, then wait for every recipient; one answer per robot."""
        started = self._clock()
        for item in publications:
            self.gateway.publish(item.topic, encode(item.command))
            deeds.published(item)
            log_event(
                "published",
                topic=item.topic,
                command_id=item.command.id,
                action=item.command.action,
                recipients=list(item.recipients),
            )
        expected = {thing: item.command.id for item in publications for thing in item.recipients}
        # With no time left the robots are still read once: an answer may already be there.
        left = self.reply_budget_s - (self._clock() - started)
        budget = max(0.0, min(self.ack_timeout_s, left))
        if self._many is not None and self._many.applies(expected):
            answers = self._many(expected, budget)
        else:
            answers = await_acknowledgments(self.gateway, expected, budget, clock=self._clock)
        log_event(
            "acknowledgments",
            outcomes={thing: answer.outcome for thing, answer in answers.items()},
            wait_ms=round((self._clock() - started) * 1000, 1),
        )
        return answers

    def shadows(self, things: Sequence[str]) -> dict[str, ShadowRead]:
        """Read the shadows of `things` concurrently; errors are kept per robot."""
        if not things:
            return {}
        with ThreadPoolExecutor(
            max_workers=min(len(things), MAX_WORKERS), thread_name_prefix="vahr-shadow"
        ) as pool:
            reads = dict(zip(things, pool.map(self._read, things), strict=True))
        return reads

    def _read(self, thing: str) -> ShadowRead:
        try:
            payload = self.gateway.get_shadow(thing)
        except GatewayError as err:
            return ShadowRead(thing, error=str(err))
        if payload is None:
            return ShadowRead(thing)
        try:
            return ShadowRead(thing, robot_shadow_from_payload(payload))
        except ProtocolError as err:
            return ShadowRead(thing, error=f"its shadow is malformed ({err})")
