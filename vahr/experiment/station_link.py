"""The session as the operator station shows it: its status, kept up to date on the broker.

While `vahr experiment` runs a session, `StatusBroadcast` publishes (retained) on
`topics.EXPERIMENT_STATUS` the participant's briefing (method, trial, task I zones), the
task under way, the judge's verdict so far for each task, the actions the paper's procedure
allows in the current task, the puzzle count and the task III LED, whenever any of it
changes. The weather is left out: the keyboard-and-mouse participant learns it by asking.

The session's MQTT connection carries a last will that clears the retained status, so a
station does not show a session whose runner died. At the end the final status goes out
once (`ended`), then the retained one is cleared.

What the participant does on the station comes back on `topics.EXPERIMENT_INPUT` and is
logged by the `Recorder`.
"""

from __future__ import annotations

import logging
import threading
from datetime import UTC, datetime
from typing import TYPE_CHECKING

import msgspec

from vahr.errors import VahrError
from vahr.experiment.eventlog import Kind
from vahr.experiment.judge import judge_task, score_goal, task_deliveries, task_windows
from vahr.experiment.procedures import PROCEDURE, allowed_actions, conformance, procedure_for
from vahr.experiment.tasks import TASK_TITLES, TASKS
from vahr.protocol import topics
from vahr.protocol.station_topics import ExperimentStatus, ExperimentTaskStatus, TaskState

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.experiment.eventlog import LogEntry
    from vahr.experiment.recorder import Recorder
    from vahr.experiment.session import OpenSession

log = logging.getLogger(__name__)

# How often the log is looked at for changes when nothing wakes the broadcast sooner.
CHECK_S = 0.25
# The will of the session's connection: an empty retained status, which clears it.
WILL = (topics.EXPERIMENT_STATUS, b"")


def task_statuses(entries: list[LogEntry], session: OpenSession) -> dict[str, ExperimentTaskStatus]:
    """Each task's state and the judge's verdict so far."""
    plan = session.plan
    header = next((e.data for e in entries if e.kind == Kind.SESSION_STARTED), {})
    windows = task_windows(entries)
    found: dict[str, ExperimentTaskStatus] = {}
    for task in TASKS:
        window = windows.get(task)
        title = TASK_TITLES[task]
        if window is None:
            found[task] = ExperimentTaskStatus("waiting", title=title)
            continue
        if window.end is not None:
            outcome = judge_task(window, plan.goal(task), plan, header)
            ended: TaskState = "success" if outcome.success else "failure"
            found[task] = ExperimentTaskStatus(
                ended, outcome.reason, title, window.start.at, window.end.at
            )
            continue
        verdict = score_goal(plan.goal(task), task_deliveries(window.entries))
        problems: list[str] = []
        if header.get("procedure") == PROCEDURE:
            procedure = procedure_for(session.spec.method, task, plan, None)
            robots = [str(r) for r in header.get("robots") or plan.goal(task).zones]
            problems = conformance(procedure, window.entries, robots)
        state: TaskState
        if problems:
            state, reason = "failure", "; ".join(problems)
        elif verdict.success is None:
            state, reason = "running", verdict.reason
        else:
            state, reason = ("success" if verdict.success else "failure"), verdict.reason
        found[task] = ExperimentTaskStatus(state, reason, title, window.start.at)
    return found


def session_status(
    entries: list[LogEntry], session: OpenSession, recorder: Recorder, *, ended: bool = False
) -> ExperimentStatus:
    spec = session.spec
    started = next((e.at for e in entries if e.kind == Kind.SESSION_STARTED), None)
    puzzle = sum(
        int(e.data.get("count", 1))
        for e in entries
        if e.kind == Kind.OBSERVER and e.data.get("what") == "puzzle_piece"
    )
    task = recorder.task
    return ExperimentStatus(
        session=spec.name,
        participant=spec.participant,
        method="keyboard" if spec.method == "keyboard" else "vahr",
        trial=spec.trial,
        simulated=spec.simulated,
        assignments=dict(session.plan.assignments),
        task=task if task in TASKS else None,  # type: ignore[arg-type]
        tasks=task_statuses(entries, session),
        allowed=sorted(allowed_actions(spec.method, task)) if task else [],
        puzzle=puzzle,
        led_on=recorder.world.led_on,
        started_at=started,
        ended=ended,
        at=datetime.now(UTC),
    )


class StatusBroadcast:
    """Publish the session's status whenever its log grows (a thread; `stop()` ends it)."""

    def __init__(
        self,
        session: OpenSession,
        recorder: Recorder,
        publish: Callable[[str, bytes, bool], None],
    ) -> None:
        self.session = session
        self.recorder = recorder
        self._publish = publish
        self._stopping = threading.Event()
        self._last: bytes | None = None
        self._seen = 0  # the last log entry the status was computed from
        self._thread = threading.Thread(target=self._run, name="experiment-status", daemon=True)

    def start(self) -> StatusBroadcast:
        self.publish()
        self._thread.start()
        return self

    def publish(self, *, ended: bool = False) -> None:
        entries = self.session.log.entries()
        self._seen = entries[-1].seq if entries else 0
        status = session_status(entries, self.session, self.recorder, ended=ended)
        body = msgspec.json.encode(msgspec.structs.replace(status, at=None))
        if body == self._last:
            return  # nothing the station shows has changed
        self._last = body
        try:
            self._publish(topics.EXPERIMENT_STATUS, msgspec.json.encode(status), not ended)
        except VahrError as err:
            log.warning("cannot publish the session's status: %s", err)

    def _run(self) -> None:
        while not self._stopping.is_set():
            with self.recorder.changed:
                self.recorder.changed.wait(CHECK_S)
            # Only a grown log can change what the station shows.
            if not self._stopping.is_set() and self.session.log.entries(after=self._seen):
                self.publish()

    def stop(self, *, ended: bool) -> None:
        """Stop; with `ended`, tell the stations the session is over and clear its status."""
        self._stopping.set()
        with self.recorder.changed:
            self.recorder.changed.notify_all()
        self._thread.join(timeout=5)
        if ended:
            self.publish(ended=True)
            try:
                self._publish(topics.EXPERIMENT_STATUS, b"", True)
            except VahrError as err:
                log.warning("cannot clear the session's status: %s", err)
