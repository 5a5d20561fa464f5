"""Helpers for the experiment's unit tests: hand-written session logs with explicit times."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING, Any

import pytest

from vahr.experiment.eventlog import EventLog, Kind
from vahr.experiment.tasks import Plan, TaskGoal

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

T0 = datetime(2026, 11, 22, 10, 0, 0, tzinfo=UTC)


def at(seconds: float) -> datetime:
    return T0 + timedelta(seconds=seconds)


def plan(weather: str = "sunny", assignments: dict[str, str] | None = None) -> Plan:
    """The plan the hand-written logs are judged against (placebot1 -> B, placebot2 -> D)."""
    assigned = assignments or {"placebot1": "B", "placebot2": "D"}
    return Plan(
        seed=1,
        assignments=assigned,
        weather=weather,  # type: ignore[arg-type]
        weather_robot="placebot1",
        goals={
            "I": TaskGoal("I", dict(assigned)),
            "II": TaskGoal("II", {"placebot1": "A" if weather == "sunny" else "C"}),
            "III": TaskGoal(
                "III", {"placebot1": "D", "placebot2": "D"}, ("placebot1", "placebot2")
            ),
        },
    )


class SessionScript:
    """Writes a session log the way the runner would, one call per line of the story."""

    def __init__(self, log: EventLog, method: str = "vahr") -> None:
        self.log = log
        self.method = method
        self.task: str | None = None
        self._interaction = 0

    def start_session(self, the_plan: Plan, participant: str = "P01", trial: int = 1) -> None:
        self.log.append(
            Kind.SESSION_STARTED,
            {
                "participant": participant,
                "method": self.method,
                "trial": trial,
                "seed": the_plan.seed,
                "plan": the_plan.to_json(),
                "simulated": False,
            },
            at=at(0),
        )

    def start(self, task: str, t: float) -> None:
        self.task = task
        self.log.append(Kind.TASK_STARTED, {"task": task}, task=task, at=at(t))

    def end(self, t: float) -> None:
        self.log.append(
            Kind.TASK_ENDED, {"task": self.task, "reason": "decided"}, task=self.task, at=at(t)
        )
        self.task = None

    def interact(
        self,
        t0: float,
        t1: float,
        *,
        commands: list[str] | None = None,
        text: str = "tell placebot one to deliver to zone b",
        error: str | None = None,
    ) -> str:
        self._interaction += 1
        ident = f"i{self._interaction}"
        channel = "voice" if self.method == "vahr" else "click"
        self.log.append(
            Kind.INTERACTION_STARTED,
            {"id": ident, "channel": channel, "text": text},
            task=self.task,
            at=at(t0),
        )
        body: dict[str, Any] = {
            "id": ident,
            "channel": channel,
            "text": text,
            "commands": commands if commands is not None else [f"c{ident}"],
        }
        if error:
            body["error"] = error
        self.log.append(Kind.INTERACTION_ENDED, body, task=self.task, at=at(t1))
        return ident

    def command(
        self,
        t: float,
        command_id: str,
        action: str = "deliver",
        *,
        zone: str | None = "B",
        target: str = "placebot1",
        source: str = "alexa",
    ) -> None:
        self.log.append(
            Kind.COMMAND,
            {
                "id": command_id,
                "action": action,
                "params": {"zone": zone} if zone else {},
                "target": target,
                "source": source,
            },
            task=self.task,
            at=at(t),
        )

    def robot(
        self,
        t: float,
        thing: str,
        event: str,
        zone: str | None = None,
        command_id: str | None = None,
        **extra: Any,
    ) -> None:
        body: dict[str, Any] = {"event": event, "thing": thing}
        if zone:
            body["zone"] = zone
        if command_id:
            body["command_id"] = command_id
        body.update(extra)
        self.log.append(Kind.ROBOT_EVENT, body, task=self.task, at=at(t))

    def led(self, t: float, on: bool) -> None:
        self.log.append(Kind.WORLD, {"what": "led", "on": on}, task=self.task, at=at(t))

    def puzzle(self, t: float, count: int = 1) -> None:
        self.log.append(
            Kind.OBSERVER, {"what": "puzzle_piece", "count": count}, task=self.task, at=at(t)
        )


@pytest.fixture
def script(tmp_path: Path) -> Iterator[SessionScript]:
    with EventLog.open(tmp_path / "P01-vahr-trial1.sqlite") as log:
        yield SessionScript(log)
