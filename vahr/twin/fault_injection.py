"""`POST /vahr/fault`: inject a fault into a running simulated robot (development only).

The request `{"thing": ..., "fault": "stuck"|"fail"|"offline"|"clear"|"battery", "offline_s": ...,
"percent": ...}`
is checked against the fleet, published to the robot on its development fault topic
(`vahr.protocol.fault_request`), and answered with what the robot said, within `timeout_s`. A
`battery` fault carries `percent` (0 to 100), the charge to set. The
answer is 200 `{"thing", "fault", "backend"}`, or an error whose message is one line:
404 for a robot not in the fleet, 409 for a robot that is not simulated, 504 for one that
did not answer (offline, or started without `sim.accept_faults`).
"""

from __future__ import annotations

import threading
import uuid
from typing import TYPE_CHECKING, Any

from vahr.errors import VahrError
from vahr.protocol import ProtocolError, encode, topics, utc_now
from vahr.protocol.fault_request import (
    DEFAULT_OFFLINE_S,
    FAULT_KINDS,
    FaultAnswer,
    FaultRequest,
    decode_fault_answer,
)

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.plumbing.mqtt import MqttClient

ANSWER_TIMEOUT_S = 5.0


class FaultInjector:
    """Send fault requests over `client` (the service identity) and wait for the answer."""

    def __init__(
        self, client: MqttClient, fleet: Fleet, *, timeout_s: float = ANSWER_TIMEOUT_S
    ) -> None:
        self._client = client
        self._fleet = fleet
        self._timeout_s = timeout_s
        self._waiting: dict[str, tuple[threading.Event, list[FaultAnswer]]] = {}
        self._lock = threading.Lock()
        client.subscribe(topics.ALL_FAULT_ANSWERS, self._on_answer, retained=False)

    def route(self, request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        thing, fault = request.get("thing"), request.get("fault")
        offline_s = request.get("offline_s", DEFAULT_OFFLINE_S)
        if not isinstance(thing, str) or thing not in self._fleet.robot_things:
            robots = ", ".join(self._fleet.robot_things)
            return _error(404, f"{thing!s:.40} is not a robot of the fleet; robots are {robots}")
        if fault not in FAULT_KINDS:
            return _error(400, f"fault: {fault!s:.40} is not one of {', '.join(FAULT_KINDS)}")
        if not isinstance(offline_s, int | float) or not 0 < offline_s <= 3600:
            return _error(400, "offline_s: must be a number of seconds in (0, 3600]")
        percent = request.get("percent")
        if fault == "battery":
            if isinstance(percent, bool) or not isinstance(percent, int | float):
                return _error(400, "percent: a battery fault needs a percent from 0 to 100")
            if not 0 <= percent <= 100:
                return _error(400, f"percent: {percent:g} is not a charge; give 0 to 100")
        elif percent is not None:
            return _error(400, f"percent: only a battery fault takes one, not {fault}")
        try:
            answer = self.inject(thing, fault, float(offline_s), percent)
        except VahrError as err:
            return _error(504, str(err))
        if not answer.ok:
            return _error(409, f"{thing}: {answer.reason or 'refused'}")
        return 200, {"thing": thing, "fault": fault, "backend": answer.backend}

    def inject(
        self,
        thing: str,
        fault: str,
        offline_s: float = DEFAULT_OFFLINE_S,
        percent: float | None = None,
    ) -> FaultAnswer:
        """Publish the request and wait for the robot's answer; VahrError if none comes."""
        request = FaultRequest(
            id=uuid.uuid4().hex,
            fault=fault,  # type: ignore[arg-type]
            at=utc_now(),
            offline_s=offline_s,
            percent=percent,
        )
        done: tuple[threading.Event, list[FaultAnswer]] = (threading.Event(), [])
        with self._lock:
            self._waiting[request.id] = done
        try:
            self._client.publish(topics.robot_fault(thing), encode(request), qos=1)
            if not done[0].wait(self._timeout_s):
                raise VahrError(
                    f"{thing} did not answer within {self._timeout_s:g} s: it is offline, or "
                    "not a simulated robot of this stack (vahr up starts them with "
                    "sim.accept_faults)"
                )
        finally:
            with self._lock:
                self._waiting.pop(request.id, None)
        return done[1][0]

    def _on_answer(self, topic: str, payload: bytes) -> None:
        try:
            answer = decode_fault_answer(payload)
        except ProtocolError:
            return
        with self._lock:
            waiting = self._waiting.get(answer.id)
        if waiting is not None:
            waiting[1].append(answer)
            waiting[0].set()


def _error(status: int, message: str) -> tuple[int, dict[str, Any]]:
    return status, {"code": status, "message": message}
