"""Run one experiment session: draw the plan, publish it, run tasks I-III, log everything.

A session is one participant, one method, one trial. Its log lives in
`LOG_DIR/{participant}-{method}-trial{N}.sqlite`. Starting a session whose log exists
resumes it: the plan is read back from the log (never redrawn), finished tasks are kept,
the task in progress continues (its commands are not sent twice), and the world (packages,
the LED) is rebuilt from the logged robot events.

A task ends as soon as the judge can decide it (every robot delivered, or a wrong delivery)
or when `task_timeout_s` passes.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from vahr.errors import VahrError
from vahr.experiment.eventlog import EventLog, Kind, session_file, session_name
from vahr.experiment.judge import (
    TaskDeliveries,
    judge_session,
    score_goal,
    task_deliveries,
    task_windows,
)
from vahr.experiment.procedures import PROCEDURE
from vahr.experiment.tasks import TASK_TITLES, TASKS, Plan, draw_plan
from vahr.experiment.world import World

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.experiment.judge import SessionVerdict
    from vahr.experiment.recorder import Recorder
    from vahr.experiment.tasks import TaskGoal

log = logging.getLogger(__name__)


class Performer(Protocol):
    """Whoever performs the tasks: the simulated participant, or a person and an observer."""

    simulated: bool

    def perform(self, task: str, done: list[str]) -> None:
        """Start the task; `done` lists the interactions (by text) already completed in it."""

    def wait(self, decided: Callable[[], bool], timeout_s: float) -> bool: ...


@dataclass(frozen=True, kw_only=True)
class SessionSpec:
    participant: str
    method: str
    trial: int
    seed: int
    log_dir: Path
    simulated: bool = False
    speed_factor: float = 1.0
    task_timeout_s: float = 600.0
    # Experiment seconds between one task's end and the next one's start, as when the
    # experimenter resets the floor and hands over the next task card.
    pause_s: float = 0.0

    @property
    def name(self) -> str:
        return session_name(self.participant, self.method, self.trial)

    @property
    def path(self) -> Path:
        return session_file(self.log_dir, self.participant, self.method, self.trial)


@dataclass
class OpenSession:
    spec: SessionSpec
    log: EventLog
    plan: Plan
    resumed: bool


def open_session(spec: SessionSpec, fleet: Fleet) -> OpenSession:
    """Create the session's log with a freshly drawn plan, or resume the existing one."""
    event_log = EventLog.open(spec.path)
    headers = event_log.entries(Kind.SESSION_STARTED)
    if not headers:
        plan = draw_plan(fleet, spec.seed)
        event_log.append(
            Kind.SESSION_STARTED,
            {
                "session": spec.name,
                "participant": spec.participant,
                "method": spec.method,
                "trial": spec.trial,
                "seed": spec.seed,
                "simulated": spec.simulated,
                "speed_factor": spec.speed_factor,
                "robots": list(fleet.robot_things),
                "plan": plan.to_json(),
                # The procedures the session follows: the judge checks the orders against them.
                "procedure": PROCEDURE,
            },
        )
        return OpenSession(spec, event_log, plan, resumed=False)
    header = headers[0].data
    if event_log.entries(Kind.SESSION_ENDED):
        event_log.close()
        raise VahrError(
            f"session {spec.name} is already complete ({spec.path}); use another trial number"
        )
    if header.get("seed") != spec.seed:
        log.warning("resuming %s with its logged seed %s", spec.name, header.get("seed"))
    event_log.append(Kind.SESSION_RESUMED, {"seed_requested": spec.seed})
    return OpenSession(spec, event_log, Plan.from_json(header["plan"]), resumed=True)


def rebuild_world(fleet: Fleet, session: OpenSession) -> World:
    """The world as the logged robot events left it (all of them, on resume)."""
    world = World.from_fleet(fleet)
    for entry in session.log.entries(Kind.ROBOT_EVENT):
        world.apply(entry.data)
    # The LED is as it was last logged: only a running task III may switch it.
    leds = [e for e in session.log.entries(Kind.WORLD) if e.data.get("what") == "led"]
    world.led_on = bool(leds[-1].data.get("on")) if leds else False
    return world


def _decision_watch(event_log: EventLog, goal: TaskGoal, start_seq: int) -> Callable[[], bool]:
    """A cheap, repeatable check: has the task been decided by the robots' deliveries?

    It reads only the events logged since its last look, so polling it often costs little.
    """
    followed = TaskDeliveries()
    seen = start_seq

    def decided() -> bool:
        nonlocal seen
        fresh = event_log.entries(after=seen)
        if fresh:
            seen = fresh[-1].seq
            followed.add(fresh)
        return score_goal(goal, followed.deliveries).success is not None

    return decided


def run_tasks(
    session: OpenSession,
    recorder: Recorder,
    performer: Performer,
    *,
    announce: Callable[[str], None] = lambda line: None,
) -> SessionVerdict:
    """Run every task not yet finished and return the judge's verdict (see `end_session`)."""
    plan, event_log = session.plan, session.log
    ran_one = False
    for task in TASKS:
        window = task_windows(event_log.entries()).get(task)
        if window is not None and window.end is not None:
            continue
        if ran_one and session.spec.pause_s > 0:
            time.sleep(session.spec.pause_s / session.spec.speed_factor)
        ran_one = True
        goal = plan.goal(task)
        logged_commands = {
            str(e.data["id"])
            for e in (window.entries if window is not None else [])
            if e.kind == Kind.COMMAND and e.data.get("id")
        }
        recorder.set_task(task, logged_commands)
        if window is None:
            event_log.append(Kind.TASK_STARTED, {"task": task}, task=task)
            announce(f"task {task}: {TASK_TITLES[task]}")
        else:
            announce(f"task {task}: resumed")
        start_seq = window.start.seq if window else event_log.entries(Kind.TASK_STARTED)[-1].seq
        if goal.order and window is None:
            recorder.log_world(recorder.world.arm_led(goal))
        elif goal.order and window is not None:
            # Resumed mid-task: watch on from the deliveries already made in this task.
            recorder.world.arm_led(goal, task_deliveries(window.entries))
        # On resume, what was already said or clicked in this task is not done again.
        done = [
            str(e.data.get("text"))
            for e in (window.entries if window is not None else [])
            if e.kind == Kind.INTERACTION_ENDED
        ]
        performer.perform(task, done)

        finished = performer.wait(
            _decision_watch(event_log, goal, start_seq), session.spec.task_timeout_s
        )
        recorder.end_task(task, "decided" if finished else "timeout")
        outcome = judge_session(event_log.entries(), plan).tasks[task]
        announce(f"task {task}: {'success' if outcome.success else 'failure'}: {outcome.reason}")
    return judge_session(event_log.entries(), plan)


def end_session(session: OpenSession) -> SessionVerdict:
    """Close the session for good: the judge's final verdict is the log's last event.

    Call it once the recorder has stopped, so no late robot event follows the end.
    """
    verdict = judge_session(session.log.entries(), session.plan)
    session.log.append(Kind.SESSION_ENDED, {"verdict": verdict.to_json()})
    return verdict
