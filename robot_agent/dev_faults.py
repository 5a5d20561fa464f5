"""Faults injected into a running robot of the local stack (`vahr fault`; development only).

Attached only when the robot's configuration says `sim.accept_faults: true`, as `vahr up`
writes it. A simulated robot applies the fault to its backend (`SimBackend.inject_*`) or,
for `offline`, drops its connection without saying goodbye for a while; any other backend
refuses, so a real robot never pretends. Every request gets an answer on the robot's
fault answer topic.
"""

from __future__ import annotations

import asyncio
import logging
from collections import deque
from typing import TYPE_CHECKING

from robot_agent.backends.sim import SimBackend
from vahr.protocol import ProtocolError, encode, topics
from vahr.protocol.fault_request import FaultAnswer, decode_fault_request

if TYPE_CHECKING:
    from robot_agent.backends.port import NavigationBackend
    from robot_agent.link.mqtt5 import Mqtt5Link

log = logging.getLogger(__name__)


class DevFaults:
    """Route `vahr/dev/robots/{thing}/fault` to the backend; answer each request."""

    def __init__(self, *, thing: str, link: Mqtt5Link, backend: NavigationBackend) -> None:
        self.thing = thing
        self.link = link
        self.backend = backend
        self._away: asyncio.Task[None] | None = None
        # A request redelivered after the robot came back (its PUBACK lost with the
        # connection it dropped) is answered once and applied once.
        self._seen: deque[str] = deque(maxlen=64)

    def attach(self) -> None:
        self.link.add_route(topics.robot_fault(self.thing), self.on_request)

    def on_request(self, topic: str, payload: bytes) -> None:
        try:
            request = decode_fault_request(payload)
        except ProtocolError as err:
            log.warning("%s: ignoring a malformed fault request: %s", self.thing, err)
            return
        if request.id in self._seen:
            return
        self._seen.append(request.id)
        backend = self.backend
        if not isinstance(backend, SimBackend):
            self._answer(request.id, f"runs the {backend.name} backend; faults are injected "
                         "into simulated robots only")  # fmt: skip
            return
        log.warning("%s: injected fault %s", self.thing, request.fault)
        if request.fault == "stuck":
            backend.inject_stuck()
        elif request.fault == "fail":
            backend.inject_failure("an injected fault")
        elif request.fault == "clear":
            backend.clear_faults()
        elif request.fault == "battery":
            if request.percent is None:
                self._answer(request.id, "battery: a percent from 0 to 100 is needed")
                return
            backend.set_battery(request.percent)
        elif self._away is None or self._away.done():
            # Answer first: the answer cannot be sent once the connection is dropped.
            self._answer(request.id)
            self._away = asyncio.ensure_future(self.link.go_away(request.offline_s))
            return
        self._answer(request.id)

    def _answer(self, request_id: str, refusal: str | None = None) -> None:
        answer = FaultAnswer(
            id=request_id, ok=refusal is None, backend=self.backend.name, reason=refusal
        )
        self.link.publish(topics.robot_fault_answer(self.thing), encode(answer))
