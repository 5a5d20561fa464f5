"""Acknowledgments of one command to many robots, counted by the fleet index.

Reading every recipient's shadow until it reports the command (`skill.acknowledgment`)
costs a GetThingShadow per robot per round: 1,000 robots cannot all be read within the
skill's wait, and the reply then says that robots which did acknowledge did not. Past
`MANY` recipients the skill asks the index instead: how many robots report the command as
their last (`get_statistics`), until all do or the wait ends; then which of them refused,
failed or cancelled it, and which never saw it (`search_index`), so the reply can name a
few. Everyone else acknowledged.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from skill.acknowledgment import FIRST_DELAY_S, MAX_DELAY_S, RobotAnswer, classify
from skill.iot_fleet_index import IotFleetIndex
from vahr.protocol import RobotShadow

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from skill.config import SkillConfig
    from skill.iot_fleet_index import FleetIndex

# Above this many recipients of one command, acknowledgments are counted by the index (the
# same bound as a status question's shadow reads, skill.fleet_question.SHADOW_READ_MAX).
MANY = 25
_NOT_DONE = ("rejected", "failed", "cancelled")


class FleetAcknowledgments:
    """`(expected, budget_s) -> answers` for one command to many robots."""

    def __init__(
        self,
        index_factory: Callable[[], FleetIndex],
        *,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self._index_factory = index_factory
        self._index: FleetIndex | None = None
        self._clock = clock
        self._sleep = sleep

    @classmethod
    def for_config(cls, config: SkillConfig) -> FleetAcknowledgments:
        # The client is made on first use: a two-robot skill never needs it.
        return cls(lambda: IotFleetIndex.from_config(config))

    def applies(self, expected: Mapping[str, str]) -> bool:
        """Many recipients of one command."""
        return len(expected) > MANY and len(set(expected.values())) == 1

    def __call__(self, expected: Mapping[str, str], budget_s: float) -> dict[str, RobotAnswer]:
        if self._index is None:
            self._index = self._index_factory()
        index = self._index
        command_id = next(iter(expected.values()))
        saw_it = f'shadow.reported.last_command.id:"{command_id}"'
        deadline = self._clock() + budget_s
        delay = FIRST_DELAY_S
        while True:
            # Wait first: no robot has answered a command published a moment ago.
            remaining = deadline - self._clock()
            if remaining > 0:
                self._sleep(min(delay, remaining))
            if index.count(saw_it) >= len(expected) or deadline - self._clock() <= 0:
                break
            delay = min(delay * 2, MAX_DELAY_S)
        answers: dict[str, RobotAnswer] = {}
        results = " OR ".join(f"shadow.reported.last_command.result:{r}" for r in _NOT_DONE)
        for robot in index.search(f"{saw_it} AND ({results})", len(expected)):
            found = classify(robot.thing, command_id, RobotShadow(reported=robot.reported))
            if robot.thing in expected and found is not None:
                answers[robot.thing] = found
        for robot in index.search(f"shadow.reported.status:* AND NOT {saw_it}", len(expected)):
            if robot.thing in expected:
                shadow = RobotShadow(reported=robot.reported)
                answers[robot.thing] = RobotAnswer(
                    robot.thing, command_id, "unconfirmed", shadow=shadow
                )
        last_count = index.count(saw_it)
        acknowledged = last_count - sum(1 for a in answers.values() if a.outcome in _NOT_DONE)
        if len(expected) - len(answers) > acknowledged:
            # Some recipients are not in the index at all (they never reported): only the
            # ones that reported the command acknowledged it.
            confirmed = {robot.thing for robot in index.search(saw_it, len(expected))}
            for thing in expected:
                if thing not in answers and thing not in confirmed:
                    answers[thing] = RobotAnswer(thing, command_id, "unconfirmed")
        return {
            thing: answers.get(thing) or RobotAnswer(thing, command_id, "acknowledged")
            for thing in expected
        }
