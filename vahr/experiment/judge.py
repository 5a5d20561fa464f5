"""Score each task of a session from its event log, exactly as the paper defines success.

- Task I: each robot delivers its package to its assigned zone; a wrong zone fails.
- Task II: sunny -> zone A, rainy -> zone C; a wrong zone is a failure to interpret the
  assistant.
- Task III: both robots deliver to zone D, placebot1 first; the other order fails.
- In sessions run with the paper's procedures (the header's `procedure`), a task also fails
  when its orders break the method's procedure (`vahr.experiment.procedures.conformance`):
  a command the method does not use in the task, or an order given before what it must
  follow was visible (a robot sent on before it was loaded, placebot2 sent before
  placebot1 delivered).

A robot's first delivery inside the task decides for that robot (a package delivered to the
wrong zone cannot be taken back); only deliveries that complete a command issued during the
task count, so a robot still finishing an earlier task's command does not. A task still
waiting for a delivery when it ends fails. The same rule (`score_goal`) lights the world's
LED, so the LED and the judge cannot disagree.

Also scored: commands (each command on the wire is acknowledged by the robots it addressed
and none of them rejects it or fails it), and communication (each person-to-assistant
interaction led to at least one command; each robot-to-assistant exchange was understood).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from vahr.domain import WEATHERS
from vahr.experiment.eventlog import Kind
from vahr.experiment.metrics import rate
from vahr.experiment.procedures import PROCEDURE, conformance, heard_weather, procedure_for

if TYPE_CHECKING:
    from datetime import datetime

    from vahr.experiment.eventlog import LogEntry
    from vahr.experiment.tasks import Plan, TaskGoal

_COMMAND_FAILURES = {"rejected", "failed", "stuck"}
_COMMAND_ACKS = {
    "accepted",
    "progress",
    "arrived",
    "loaded",
    "delivered",
    "done",
    "waiting",
    "cancelled",
    "stopped",
    "said",
    "heard",
    "interpreted",
}


@dataclass(frozen=True)
class Delivery:
    """A robot's `delivered` event: which robot, which zone, when (log order), for which
    command."""

    thing: str
    zone: str | None
    seq: int
    command_id: str | None = None


@dataclass(frozen=True)
class Verdict:
    """The judge's word on one goal: success True/False, or None while still undecided."""

    success: bool | None
    reason: str


def score_goal(goal: TaskGoal, deliveries: list[Delivery], *, wrong_zone_hint: str = "") -> Verdict:
    """Score the deliveries made so far against one task's goal."""
    first: dict[str, Delivery] = {}
    for delivery in sorted(deliveries, key=lambda d: d.seq):
        if delivery.thing in goal.zones and delivery.thing not in first:
            first[delivery.thing] = delivery
    for thing, expected in goal.zones.items():
        made = first.get(thing)
        if made is not None and made.zone != expected:
            hint = f"; {wrong_zone_hint}" if wrong_zone_hint else ""
            return Verdict(False, f"{thing} delivered to {made.zone}, not {expected}{hint}")
    for earlier, later in zip(goal.order, goal.order[1:], strict=False):
        if later in first and (earlier not in first or first[earlier].seq > first[later].seq):
            return Verdict(False, f"{later} delivered before {earlier}")
    waiting = [thing for thing in goal.zones if thing not in first]
    if waiting:
        return Verdict(None, f"waiting for {', '.join(waiting)} to deliver")
    if goal.order:
        return Verdict(
            True, f"delivered to {goal.zones[goal.order[0]]} in order {', '.join(goal.order)}"
        )
    return Verdict(True, "every package delivered to its zone")


@dataclass(frozen=True)
class TaskOutcome:
    """How one task went."""

    task: str
    success: bool
    reason: str
    started_at: datetime | None
    ended_at: datetime | None
    deliveries: list[Delivery] = field(default_factory=list)
    led_on: bool | None = None  # task III only: the LED's last logged state in the task

    @property
    def duration_s(self) -> float | None:
        if self.started_at is None or self.ended_at is None:
            return None
        return (self.ended_at - self.started_at).total_seconds()

    def to_json(self) -> dict[str, Any]:
        body: dict[str, Any] = {
            "success": self.success,
            "reason": self.reason,
            "duration_s": self.duration_s,
            "deliveries": [{"thing": d.thing, "zone": d.zone} for d in self.deliveries],
        }
        if self.led_on is not None:
            body["led_on"] = self.led_on
        return body


@dataclass(frozen=True)
class SuccessTally:
    """Successes out of attempts, with the reason of each failure."""

    successes: int = 0
    total: int = 0
    failures: tuple[str, ...] = ()

    @property
    def success_rate(self) -> float | None:
        return rate(self.successes, self.total)

    @property
    def failure_rate(self) -> float | None:
        return rate(self.total - self.successes, self.total)

    def to_json(self) -> dict[str, Any]:
        return {
            "successes": self.successes,
            "total": self.total,
            "success_rate": self.success_rate,
            "failure_rate": self.failure_rate,
            "failures": list(self.failures),
        }


@dataclass(frozen=True)
class SessionVerdict:
    tasks: dict[str, TaskOutcome]
    commands: SuccessTally
    communication: SuccessTally

    @property
    def task_tally(self) -> SuccessTally:
        outcomes = list(self.tasks.values())
        return SuccessTally(
            successes=sum(outcome.success for outcome in outcomes),
            total=len(outcomes),
            failures=tuple(f"task {o.task}: {o.reason}" for o in outcomes if not o.success),
        )

    def to_json(self) -> dict[str, Any]:
        return {
            "tasks": {task: outcome.to_json() for task, outcome in self.tasks.items()},
            "task_success": self.task_tally.to_json(),
            "command_success": self.commands.to_json(),
            "communication_success": self.communication.to_json(),
        }


@dataclass(frozen=True)
class TaskWindow:
    """The log entries from a task's start to its end (or the end of the log)."""

    task: str
    start: LogEntry
    end: LogEntry | None
    entries: list[LogEntry]


def task_windows(entries: list[LogEntry]) -> dict[str, TaskWindow]:
    """Each task's window: its first start to the first end after it.

    A session resumed after a crash continues the task in progress without a new start, so
    the window spans the interruption.
    """
    windows: dict[str, TaskWindow] = {}
    open_tasks: dict[str, tuple[LogEntry, list[LogEntry]]] = {}
    for entry in entries:
        for _, inside in open_tasks.values():
            inside.append(entry)
        if entry.kind == Kind.TASK_STARTED:
            task = str(entry.data["task"])
            if task not in windows and task not in open_tasks:
                open_tasks[task] = (entry, [])
        elif entry.kind == Kind.TASK_ENDED:
            task = str(entry.data["task"])
            if task in open_tasks:
                start, inside = open_tasks.pop(task)
                windows[task] = TaskWindow(task, start, entry, inside[:-1])
    for task, (start, inside) in open_tasks.items():
        windows[task] = TaskWindow(task, start, None, inside)
    return windows


def deliveries_in(entries: list[LogEntry]) -> list[Delivery]:
    """Every `delivered` event among `entries`."""
    return [
        Delivery(
            thing=str(e.data.get("thing")),
            zone=e.data.get("zone"),
            seq=e.seq,
            command_id=e.data.get("command_id"),
        )
        for e in entries
        if e.kind == Kind.ROBOT_EVENT and e.data.get("event") == "delivered"
    ]


class TaskDeliveries:
    """The deliveries that belong to one task, followed as the log grows.

    A delivery belongs to the task when it completes a command seen on the wire during the
    task. A robot still finishing an earlier task's command (after a task was decided early
    by a wrong delivery, or a session ended with robots under way) delivers for that older
    command, which must not count here. A delivery that names no command counts.
    """

    def __init__(self) -> None:
        self.commands: set[str] = set()
        self.deliveries: list[Delivery] = []

    def add(self, entries: list[LogEntry]) -> None:
        for entry in entries:
            if entry.kind == Kind.COMMAND and entry.data.get("id"):
                self.commands.add(str(entry.data["id"]))
            elif entry.kind == Kind.ROBOT_EVENT and entry.data.get("event") == "delivered":
                (delivery,) = deliveries_in([entry])
                if delivery.command_id is None or delivery.command_id in self.commands:
                    self.deliveries.append(delivery)


def task_deliveries(entries: list[LogEntry]) -> list[Delivery]:
    """The deliveries among a task's entries that complete the task's own commands."""
    followed = TaskDeliveries()
    followed.add(entries)
    return followed.deliveries


def _failure_context(window: TaskWindow, waiting: list[str]) -> str:
    """The last thing that went wrong for the robots still awaited, to explain a failure."""
    for entry in reversed(window.entries):
        data = entry.data
        if (
            entry.kind == Kind.ROBOT_EVENT
            and data.get("thing") in waiting
            and data.get("event") in {"failed", "stuck", "rejected", "cancelled", "stopped"}
        ):
            why = f": {data['reason']}" if data.get("reason") else ""
            return f" (last: {data['thing']} {data['event']}{why})"
    return ""


def judge_task(
    window: TaskWindow, goal: TaskGoal, plan: Plan, header: dict[str, Any] | None = None
) -> TaskOutcome:
    """Score one task; `header` (the session's) says which procedure its orders follow."""
    hint = ""
    if goal.task == "II":
        hint = f"the weather was {plan.weather}: a failure to interpret the assistant"
    deliveries = task_deliveries(window.entries)
    verdict = score_goal(goal, deliveries, wrong_zone_hint=hint)
    success, reason = verdict.success, verdict.reason
    if success is None:
        waiting = [t for t in goal.zones if t not in {d.thing for d in deliveries}]
        how = "ended" if window.end is not None else "was interrupted"
        reason = f"the task {how} before {', '.join(waiting)} delivered"
        reason += _failure_context(window, waiting)
        success = False
    if header is not None and header.get("procedure") == PROCEDURE:
        procedure = procedure_for(str(header.get("method")), goal.task, plan, None)
        robots = [str(r) for r in header.get("robots") or goal.zones]
        problems = conformance(procedure, window.entries, robots)
        if problems:
            reason = "; ".join(problems) + (f"; {reason}" if not success else "")
            success = False
    led_on: bool | None = None
    if goal.order:
        led_on = False
        for entry in window.entries:
            if entry.kind == Kind.WORLD and entry.data.get("what") == "led":
                led_on = bool(entry.data.get("on"))
    return TaskOutcome(
        task=goal.task,
        success=success,
        reason=reason,
        started_at=window.start.at,
        ended_at=window.end.at if window.end is not None else None,
        deliveries=[d for d in deliveries if d.thing in goal.zones],
        led_on=led_on,
    )


def judge_commands(entries: list[LogEntry]) -> SuccessTally:
    """Each command on the wire succeeds when acknowledged and neither rejected nor failed."""
    events_by_command: dict[str, list[dict[str, Any]]] = {}
    for entry in entries:
        if entry.kind == Kind.ROBOT_EVENT and entry.data.get("command_id"):
            events_by_command.setdefault(str(entry.data["command_id"]), []).append(entry.data)
    successes, total, failures = 0, 0, []
    for entry in entries:
        if entry.kind != Kind.COMMAND or str(entry.data.get("source", "")).startswith("robot:"):
            continue  # robot-to-robot commands are the robots' business, not the person's
        total += 1
        command_id = str(entry.data.get("id"))
        seen = events_by_command.get(command_id, [])
        bad = [e for e in seen if e.get("event") in _COMMAND_FAILURES]
        if bad:
            why = f": {bad[0]['reason']}" if bad[0].get("reason") else ""
            failures.append(f"{entry.data.get('action')} {command_id} {bad[0]['event']}{why}")
        elif any(e.get("event") in _COMMAND_ACKS for e in seen):
            successes += 1
        else:
            failures.append(f"{entry.data.get('action')} {command_id} was never acknowledged")
    return SuccessTally(successes, total, tuple(failures))


def judge_communication(entries: list[LogEntry]) -> SuccessTally:
    """Person-to-assistant interactions that led to a command, and robot-to-assistant
    exchanges whose answer was understood."""
    successes, total, failures = 0, 0, []
    for entry in entries:
        if entry.kind == Kind.INTERACTION_ENDED:
            if not entry.data.get("counts", True):
                continue  # a glance, or a click that only selects, sends nothing by design
            total += 1
            if entry.data.get("asks") and not entry.data.get("error"):
                # A question to the assistant succeeds when its answer names the weather.
                if heard_weather(str(entry.data.get("speech", ""))) is not None:
                    successes += 1
                else:
                    failures.append(f"{entry.data.get('text')!r}: the answer named no weather")
            elif entry.data.get("commands") and not entry.data.get("error"):
                successes += 1
            else:
                said = entry.data.get("text") or entry.data.get("id")
                why = entry.data.get("error") or "no command resulted"
                failures.append(f"{said!r}: {why}")
        elif entry.kind == Kind.ROBOT_EVENT and entry.data.get("event") == "interpreted":
            total += 1
            if entry.data.get("intent") in WEATHERS:
                successes += 1
            else:
                failures.append(
                    f"{entry.data.get('thing')} did not understand {entry.data.get('text')!r}"
                )
    return SuccessTally(successes, total, tuple(failures))


def judge_session(entries: list[LogEntry], plan: Plan) -> SessionVerdict:
    """Score every task of the plan (a task never started fails), commands and communication."""
    windows = task_windows(entries)
    header = next((e.data for e in entries if e.kind == Kind.SESSION_STARTED), None)
    outcomes: dict[str, TaskOutcome] = {}
    for task, goal in plan.goals.items():
        window = windows.get(task)
        if window is None:
            outcomes[task] = TaskOutcome(task, False, "the task was not run", None, None)
        else:
            outcomes[task] = judge_task(window, goal, plan, header)
    return SessionVerdict(outcomes, judge_commands(entries), judge_communication(entries))
