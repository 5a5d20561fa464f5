"""Wait, within a budget, until robots report a command id in their shadows.

Each robot's shadow is polled in its own worker with a short exponential backoff (reads at
50, 150, 350 and 750 ms, then every 400 ms, and once more at the deadline), so one slow
robot does not delay the others. A robot counts as having answered when
`reported.last_command.id` equals the command id; its `result` says how.
"""

from __future__ import annotations

import logging
import threading
import time
from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait
from typing import TYPE_CHECKING, Literal

import msgspec

from skill.errors import GatewayError
from skill.logs import log_event
from vahr.protocol import ProtocolError, RobotShadow, robot_shadow_from_payload

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from skill.gateway import RobotGateway
Outcome = Literal["acknowledged", "rejected", "failed", "cancelled", "unconfirmed"]

FIRST_DELAY_S = 0.05
MAX_DELAY_S = 0.4
MAX_WORKERS = 8
# Workers stop polling at the deadline; this covers one read still in flight then.
GRACE_S = 0.3


class RobotAnswer(msgspec.Struct, frozen=True):
    """What became of one command at one robot when the wait ended."""

    thing: str
    command_id: str
    outcome: Outcome
    reason: str | None = None
    shadow: RobotShadow | None = None  # the last shadow read, for presence
    error: str | None = None  # the last read error, if any

    @property
    def confirmed(self) -> bool:
        return self.outcome == "acknowledged"

    @property
    def offline(self) -> bool:
        """True when the robot's shadow says it is disconnected, or it never reported."""
        return self.shadow is None or not self.shadow.reported.connected


def classify(thing: str, command_id: str, shadow: RobotShadow) -> RobotAnswer | None:
    """The answer if the shadow reports `command_id`, else None (keep waiting)."""
    last = shadow.reported.last_command
    if last is None or last.id != command_id:
        return None
    outcome: Outcome = "acknowledged"
    if last.result in ("rejected", "failed", "cancelled"):
        outcome = last.result  # type: ignore[assignment]
    return RobotAnswer(thing, command_id, outcome, last.reason, shadow)


def await_acknowledgments(
    gateway: RobotGateway,
    expected: Mapping[str, str],
    budget_s: float,
    *,
    clock: Callable[[], float] = time.monotonic,
) -> dict[str, RobotAnswer]:
    """Poll each thing's shadow until it reports its command id or `budget_s` runs out.

    `expected` maps thing name to command id. Returns one answer per thing.
    """
    if not expected:
        return {}
    deadline = clock() + budget_s
    stop = threading.Event()
    pool = ThreadPoolExecutor(
        max_workers=min(len(expected), MAX_WORKERS), thread_name_prefix="vahr-ack"
    )
    try:
        futures = {
            thing: pool.submit(_poll, gateway, thing, command_id, deadline, stop, clock)
            for thing, command_id in expected.items()
        }
        wait(futures.values(), timeout=budget_s + GRACE_S, return_when=FIRST_EXCEPTION)
    finally:
        stop.set()
        # A read still in flight ends on its own within the client's timeouts; the answer
        # must not wait for it.
        pool.shutdown(wait=False, cancel_futures=True)
    answers = {}
    for thing, future in futures.items():
        if future.done() and not future.cancelled() and future.exception() is None:
            answers[thing] = future.result()
            continue
        error = "no answer within the budget"
        if future.done() and not future.cancelled():
            error = f"{type(future.exception()).__name__}: {future.exception()}"
            log_event("acknowledgment_worker_failed", logging.ERROR, thing=thing, error=error)
        answers[thing] = RobotAnswer(thing, expected[thing], "unconfirmed", error=error)
    return answers


def _poll(
    gateway: RobotGateway,
    thing: str,
    command_id: str,
    deadline: float,
    stop: threading.Event,
    clock: Callable[[], float],
) -> RobotAnswer:
    delay = FIRST_DELAY_S
    shadow: RobotShadow | None = None
    error: str | None = None
    while True:
        # Wait before each read, the first included: a robot cannot have answered a command
        # published a moment ago, and every read is billed. With no time left, read once.
        remaining = deadline - clock()
        if remaining > 0 and stop.wait(min(delay, remaining)):
            return RobotAnswer(thing, command_id, "unconfirmed", shadow=shadow, error=error)
        try:
            payload = gateway.get_shadow(thing)
            # Tolerant: a robot reporting a status this skill does not know yet must still
            # be heard acknowledging its command.
            shadow = (
                robot_shadow_from_payload(payload, tolerant=True) if payload is not None else None
            )
            error = None
        except (GatewayError, ProtocolError) as err:
            error = str(err)
        if shadow is not None and (answer := classify(thing, command_id, shadow)) is not None:
            return answer
        if deadline - clock() <= 0:
            return RobotAnswer(thing, command_id, "unconfirmed", shadow=shadow, error=error)
        delay = min(delay * 2, MAX_DELAY_S)
