"""A whole simulated study: every participant, both methods, every trial, then the report.

`run_study` is what `vahr rehearse` runs against a live system (its broker and data plane).
The design follows the paper where it is stated and a careful choice where it is not
(docs/experiment.md, "Rehearsing a study"):

- participants P01..PN, each one `timing.Person` drawn from the study's seed;
- methods counterbalanced (the paper does not say how): odd-numbered participants start
  with VAHR, even-numbered ones with the keyboard and mouse (AB/BA);
- per method the trials 1..T in a row (the warm-up is not simulated: the model does not
  learn);
- each session's plan (zones, weather) drawn from the session's own seed, as
  `vahr experiment` draws it.

The session logs go to `OUT/logs`; the report (`vahr.experiment.report`) and the paper's
Table II beside it (`vahr.experiment.paper`) to `OUT`. A study stopped half way continues:
finished sessions are kept, an interrupted one resumes.
"""

from __future__ import annotations

import hashlib
import json
import random
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from vahr.experiment.eventlog import Kind, read_log, session_file
from vahr.experiment.live_session import run_simulated_session
from vahr.experiment.paper import compare, render_comparison
from vahr.experiment.report import write_report
from vahr.experiment.results import row_from_log, rows_from_logs
from vahr.experiment.tasks import METHODS, default_seed
from vahr.experiment.timing import Person
from vahr.plumbing.client import HttpAssistant

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.domain import Fleet


@dataclass(frozen=True, kw_only=True)
class StudySpec:
    participants: int
    trials: int
    out_dir: Path
    speed_factor: float
    seed: int = 1
    task_timeout_s: float = 600.0
    monitoring: str = "glance"

    @property
    def log_dir(self) -> Path:
        return self.out_dir / "logs"


def participant_ids(count: int) -> list[str]:
    return [f"P{number:02d}" for number in range(1, count + 1)]


def counterbalanced_methods(position: int) -> tuple[str, ...]:
    """AB/BA counterbalancing: the first participant starts with VAHR, the next with the
    keyboard and mouse, and so on."""
    return METHODS if position % 2 == 0 else tuple(reversed(METHODS))


def person_for(study_seed: int, participant: str, monitoring: str = "glance") -> Person:
    """The participant's tempo, the same for every session of theirs and every rerun."""
    digest = hashlib.sha256(f"{study_seed}\x00{participant}".encode()).digest()
    return Person.draw(random.Random(int.from_bytes(digest[:8], "big")), monitoring)


def _finished(path: Path) -> bool:
    return path.exists() and any(e.kind == Kind.SESSION_ENDED for e in read_log(path))


def run_study(
    spec: StudySpec,
    fleet: Fleet,
    *,
    broker_url: str,
    api_url: str,
    announce: Callable[[str], None] = lambda line: None,
) -> dict[str, Any]:
    """Run every session not yet finished, then write the report; return report.json."""
    assistant = HttpAssistant(api_url)
    for position, participant in enumerate(participant_ids(spec.participants)):
        person = person_for(spec.seed, participant, spec.monitoring)
        for method in counterbalanced_methods(position):
            for trial in range(1, spec.trials + 1):
                path = session_file(spec.log_dir, participant, method, trial)
                if _finished(path):
                    announce(f"{participant} {method} trial {trial}: already finished, kept")
                    continue
                verdict, path = run_simulated_session(
                    fleet=fleet,
                    method=method,
                    log_dir=spec.log_dir,
                    broker_url=broker_url,
                    assistant=assistant,
                    participant=participant,
                    trial=trial,
                    seed=default_seed(participant, method, trial) ^ spec.seed,
                    speed_factor=spec.speed_factor,
                    task_timeout_s=spec.task_timeout_s,
                    data_plane_url=api_url,
                    person=person,
                )
                row = row_from_log(read_log(path))
                tasks = verdict.task_tally
                announce(
                    f"{participant} {method} trial {trial}: tasks {tasks.successes}/"
                    f"{tasks.total}, IE {row.interaction_time_s:.1f} s, "
                    f"NT {row.neglect_time_s:.1f} s, RAD {row.rad:.2f}, "
                    f"puzzle {row.puzzle_parts}"
                    + (f" ({'; '.join(tasks.failures)})" if tasks.failures else "")
                )
    return write_study_report(spec)


def write_study_report(spec: StudySpec) -> dict[str, Any]:
    """The report of the study's logs, with the paper's Table II beside it."""
    rows, _ = rows_from_logs(spec.log_dir)
    report = write_report(rows, spec.out_dir, source=str(spec.log_dir), simulated=True)
    report["paper_comparison"] = compare(report)
    report["study"] = {
        "participants": spec.participants,
        "trials": spec.trials,
        "speed_factor": spec.speed_factor,
        "seed": spec.seed,
        "monitoring": spec.monitoring,
        "counterbalancing": "AB/BA: odd-numbered participants start with vahr",
    }
    (spec.out_dir / "report.json").write_text(json.dumps(report, indent=2) + "\n")
    table = render_comparison(report["paper_comparison"])
    markdown = (spec.out_dir / "report.md").read_text()
    heading = "## Objective results (Table II)"
    beside = (
        "## Beside the paper's Table II (simulated)\n\n"
        "The paper's means per method and p (one-way ANOVA), this rehearsal's, and whether "
        "the direction of the VAHR - keyboard difference agrees.\n\n" + table + "\n"
    )
    (spec.out_dir / "report.md").write_text(markdown.replace(heading, beside + heading, 1))
    return report
