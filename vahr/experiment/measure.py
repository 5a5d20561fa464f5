"""Interaction effort, neglect time and time taken, measured from a session's event log.

For each task, between its `task_started` and `task_ended` events:

- time taken T = task_ended - task_started;
- interaction effort IE = the total length of the union of the participant's interaction
  intervals inside the task: for the voice method each interval runs from the moment the
  participant starts speaking to the end of the assistant's spoken reply (the person is
  busy with the robots for the whole exchange, listening included); for the keyboard and
  mouse method each interval runs from the start of the pointing movement to the release of
  the click. Overlapping intervals count once, and intervals are clipped to the task;
- neglect time NT = T - IE: the time the robots work while the person does something else
  (the puzzle).

A session's totals are the sums over its tasks, so IE + NT = T as in the paper's Table II.
An interaction whose end was never logged (a crash mid-utterance) is not counted, and is
reported in `unclosed_interactions`.

A rehearsal with simulated robots and a simulated participant may run faster than real
time; its header then records `speed_factor` (experiment seconds per wall-clock second),
and every duration measured here is multiplied by it. Sessions with people have factor 1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from vahr.experiment.eventlog import Kind
from vahr.experiment.judge import task_windows

if TYPE_CHECKING:
    from datetime import datetime

    from vahr.experiment.eventlog import LogEntry


@dataclass(frozen=True)
class TaskTimes:
    task: str
    time_taken_s: float
    interaction_s: float
    interactions: int

    @property
    def neglect_s(self) -> float:
        return max(0.0, self.time_taken_s - self.interaction_s)

    def to_json(self) -> dict[str, Any]:
        return {
            "time_taken_s": self.time_taken_s,
            "interaction_time_s": self.interaction_s,
            "neglect_time_s": self.neglect_s,
            "interactions": self.interactions,
        }


@dataclass(frozen=True)
class SessionTimes:
    tasks: dict[str, TaskTimes]
    puzzle_parts: int
    unclosed_interactions: int

    @property
    def interaction_s(self) -> float:
        return sum(t.interaction_s for t in self.tasks.values())

    @property
    def neglect_s(self) -> float:
        return sum(t.neglect_s for t in self.tasks.values())

    @property
    def time_taken_s(self) -> float:
        return sum(t.time_taken_s for t in self.tasks.values())

    def to_json(self) -> dict[str, Any]:
        return {
            "interaction_time_s": self.interaction_s,
            "neglect_time_s": self.neglect_s,
            "task_time_s": self.time_taken_s,
            "puzzle_parts": self.puzzle_parts,
            "unclosed_interactions": self.unclosed_interactions,
            "tasks": {task: times.to_json() for task, times in self.tasks.items()},
        }


def interaction_intervals(entries: list[LogEntry]) -> tuple[list[tuple[datetime, datetime]], int]:
    """(start, end) of each closed interaction, and how many were never closed."""
    started: dict[str, datetime] = {}
    intervals: list[tuple[datetime, datetime]] = []
    for entry in entries:
        if entry.kind == Kind.INTERACTION_STARTED:
            started[str(entry.data["id"])] = entry.at
        elif entry.kind == Kind.INTERACTION_ENDED:
            begin = started.pop(str(entry.data["id"]), None)
            if begin is not None and entry.at >= begin:
                intervals.append((begin, entry.at))
    return intervals, len(started)


def union_length_s(
    intervals: list[tuple[datetime, datetime]], start: datetime, end: datetime
) -> float:
    """The total length of the union of `intervals`, clipped to [start, end], in seconds."""
    clipped = sorted((max(a, start), min(b, end)) for a, b in intervals if b > start and a < end)
    total = 0.0
    current: tuple[datetime, datetime] | None = None
    for a, b in clipped:
        if current is None or a > current[1]:
            if current is not None:
                total += (current[1] - current[0]).total_seconds()
            current = (a, b)
        elif b > current[1]:
            current = (current[0], b)
    if current is not None:
        total += (current[1] - current[0]).total_seconds()
    return total


def speed_factor(entries: list[LogEntry]) -> float:
    """Experiment seconds per wall-clock second, from the session header (1 if absent)."""
    for entry in entries:
        if entry.kind == Kind.SESSION_STARTED:
            return float(entry.data.get("speed_factor", 1.0))
    return 1.0


def measure_session(entries: list[LogEntry]) -> SessionTimes:
    """IE, NT and T of every finished task, and the puzzle parts solved in the session."""
    intervals, unclosed = interaction_intervals(entries)
    factor = speed_factor(entries)
    tasks: dict[str, TaskTimes] = {}
    for task, window in task_windows(entries).items():
        if window.end is None:
            continue  # an unfinished task has no time taken; the judge reports it failed
        start, end = window.start.at, window.end.at
        inside = [(a, b) for a, b in intervals if b > start and a < end]
        tasks[task] = TaskTimes(
            task=task,
            time_taken_s=(end - start).total_seconds() * factor,
            interaction_s=union_length_s(intervals, start, end) * factor,
            interactions=len(inside),
        )
    puzzle = sum(
        int(entry.data.get("count", 1))
        for entry in entries
        if entry.kind == Kind.OBSERVER and entry.data.get("what") == "puzzle_piece"
    )
    return SessionTimes(tasks=tasks, puzzle_parts=puzzle, unclosed_interactions=unclosed)
