"""The results table: one row per participant, method and trial (the report's CSV).

Columns: participant, method, trial, interaction_time_s, neglect_time_s, task_time_s,
puzzle_parts, and the questionnaire's eight items as levels 1-21 (mental, physical,
temporal, performance, effort, frustration, confidence, trust). A run without a
questionnaire (a simulated one) leaves all eight empty. Rows come from a CSV file or from
session logs (`rows_from_logs`).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from vahr.errors import VahrError
from vahr.experiment.eventlog import Kind, find_logs, read_log
from vahr.experiment.judge import judge_session
from vahr.experiment.measure import measure_session
from vahr.experiment.metrics import fan_out, rad, trust_adjusted_rad
from vahr.experiment.tasks import Plan
from vahr.experiment.tlx import ITEMS, TlxAnswers, check_level

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.experiment.eventlog import LogEntry

COLUMNS = (
    "participant",
    "method",
    "trial",
    "interaction_time_s",
    "neglect_time_s",
    "task_time_s",
    "puzzle_parts",
    *ITEMS,
)


@dataclass(frozen=True)
class ResultRow:
    participant: str
    method: str
    trial: int
    interaction_time_s: float
    neglect_time_s: float
    task_time_s: float
    puzzle_parts: int
    tlx: TlxAnswers | None
    # (successes, total) of tasks, commands and communication, when measured from a log.
    tallies: dict[str, tuple[int, int]] | None = None

    def __post_init__(self) -> None:
        # RAD = IE / (IE + NT) and fan-out = task time / RAD: with no interaction at all
        # neither is defined, and no report could be drawn from the row.
        if self.interaction_time_s + self.neglect_time_s == 0:
            raise VahrError("interaction and neglect time are both 0; RAD is undefined")
        if self.interaction_time_s == 0:
            raise VahrError("interaction_time_s is 0; fan-out (task time / RAD) is undefined")

    @property
    def rad(self) -> float:
        """RAD of this row: IE / (IE + NT)."""
        return rad(self.interaction_time_s, self.neglect_time_s)

    @property
    def fan_out(self) -> float:
        """Fan-out of this row: task time / RAD."""
        return fan_out(self.task_time_s, self.rad)

    @property
    def trust_adjusted(self) -> float | None:
        """DIT + NT x (1 - Tr) with the row's trust answer, or None without a questionnaire."""
        if self.tlx is None:
            return None
        trust = self.tlx.percents()["trust"] / 100
        return trust_adjusted_rad(self.interaction_time_s, self.neglect_time_s, trust)

    def to_csv(self) -> dict[str, object]:
        row: dict[str, object] = {
            "participant": self.participant,
            "method": self.method,
            "trial": self.trial,
            "interaction_time_s": round(self.interaction_time_s, 3),
            "neglect_time_s": round(self.neglect_time_s, 3),
            "task_time_s": round(self.task_time_s, 3),
            "puzzle_parts": self.puzzle_parts,
        }
        levels = self.tlx.levels() if self.tlx is not None else {}
        for item in ITEMS:
            row[item] = levels.get(item, "")
        return row


# The objective metrics the report compares and draws: each one's label, unit and value in
# a row.
OBJECTIVE: dict[str, tuple[str, str, Callable[[ResultRow], float]]] = {
    "interaction_time": ("Interaction time (IE)", "s", lambda r: r.interaction_time_s),
    "neglect_time": ("Neglect time (NT)", "s", lambda r: r.neglect_time_s),
    "rad": ("RAD = IE / (IE + NT)", "", lambda r: r.rad),
    "fan_out": ("Fan-out = time / RAD", "s", lambda r: r.fan_out),
    "puzzle_parts": ("Solved puzzle parts", "", lambda r: float(r.puzzle_parts)),
    "time_taken": ("Time taken", "s", lambda r: r.task_time_s),
}


def _number(line: int, column: str, text: str, *, whole: bool = False) -> float:
    try:
        value = float(text)
    except ValueError:
        raise VahrError(f"row {line}: {column} {text!r} is not a number") from None
    if not math.isfinite(value) or value < 0 or (whole and not value.is_integer()):
        kind = "a whole number" if whole else "a number"
        raise VahrError(f"row {line}: {column} {text!r} is not {kind} >= 0")
    return value


def parse_row(line: int, raw: dict[str, str]) -> ResultRow:
    """Validate one CSV row (line is its line number in the file, for error messages)."""

    def cell(column: str) -> str:
        value = raw.get(column)
        if value is None or not value.strip():
            raise VahrError(f"row {line}: {column} is empty")
        return value.strip()

    trial = _number(line, "trial", cell("trial"), whole=True)
    if trial < 1:
        raise VahrError(f"row {line}: trial must be 1 or more")
    answered = [item for item in ITEMS if (raw.get(item) or "").strip()]
    tlx = None
    if answered and len(answered) < len(ITEMS):
        missing = ", ".join(item for item in ITEMS if item not in answered)
        raise VahrError(
            f"row {line}: the questionnaire is incomplete ({missing} empty); "
            "give all eight items, or none for a run without a questionnaire"
        )
    if answered:
        try:
            tlx = TlxAnswers.from_mapping({item: check_level(item, cell(item)) for item in ITEMS})
        except ValueError as err:
            raise VahrError(f"row {line}: {err}") from None
    interaction = _number(line, "interaction_time_s", cell("interaction_time_s"))
    neglect = _number(line, "neglect_time_s", cell("neglect_time_s"))
    task = _number(line, "task_time_s", cell("task_time_s"))
    puzzle_parts = int(_number(line, "puzzle_parts", cell("puzzle_parts"), whole=True))
    participant, method = cell("participant"), cell("method")
    try:
        return ResultRow(
            participant=participant,
            method=method,
            trial=int(trial),
            interaction_time_s=interaction,
            neglect_time_s=neglect,
            task_time_s=task,
            puzzle_parts=puzzle_parts,
            tlx=tlx,
        )
    except VahrError as err:  # the row's own rules (ResultRow.__post_init__)
        raise VahrError(f"row {line}: {err}") from None


def read_csv(path: Path) -> list[ResultRow]:
    """Read and validate a results CSV; raise VahrError naming the row and column."""
    try:
        with path.open(newline="", encoding="utf-8-sig") as stream:
            reader = csv.DictReader(stream)
            missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise VahrError(f"{path}: missing column(s) {', '.join(missing)}")
            rows = [parse_row(reader.line_num, raw) for raw in reader]
    except OSError as err:
        raise VahrError(f"cannot read {path}: {err.strerror}") from err
    except csv.Error as err:
        raise VahrError(f"{path} is not a valid CSV file: {err}") from err
    except UnicodeDecodeError as err:
        raise VahrError(f"{path} is not UTF-8 text (byte {err.start} cannot be read)") from err
    if not rows:
        raise VahrError(f"{path} has no rows")
    return rows


def write_csv(rows: list[ResultRow], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="", encoding="utf-8") as stream:
        writer = csv.DictWriter(stream, fieldnames=COLUMNS)
        writer.writeheader()
        for row in rows:
            writer.writerow(row.to_csv())


def session_header(entries: list[LogEntry]) -> dict[str, object]:
    for entry in entries:
        if entry.kind == Kind.SESSION_STARTED:
            return entry.data
    raise VahrError("the log has no session_started event")


def latest_tlx(entries: list[LogEntry]) -> TlxAnswers | None:
    """The last questionnaire entered for the session (a re-entry replaces, never edits)."""
    answers = [entry for entry in entries if entry.kind == Kind.TLX]
    return TlxAnswers.from_mapping(answers[-1].data["levels"]) if answers else None


def row_from_log(entries: list[LogEntry]) -> ResultRow:
    header = session_header(entries)
    times = measure_session(entries)
    tallies = None
    if isinstance(header.get("plan"), dict):
        verdict = judge_session(entries, Plan.from_json(header["plan"]))  # type: ignore[arg-type]
        tallies = {
            "task": (verdict.task_tally.successes, verdict.task_tally.total),
            "command": (verdict.commands.successes, verdict.commands.total),
            "communication": (verdict.communication.successes, verdict.communication.total),
        }
    return ResultRow(
        participant=str(header["participant"]),
        method=str(header["method"]),
        trial=int(str(header["trial"])),
        interaction_time_s=times.interaction_s,
        neglect_time_s=times.neglect_s,
        task_time_s=times.time_taken_s,
        puzzle_parts=times.puzzle_parts,
        tlx=latest_tlx(entries),
        tallies=tallies,
    )


def rows_from_logs(log_dir: Path) -> tuple[list[ResultRow], list[str]]:
    """A row per finished session log under `log_dir`; the second list names the logs left
    out and why (an unfinished session would bias the sums of its task times: resume it)."""
    rows: list[ResultRow] = []
    skipped: list[str] = []
    for path in find_logs(log_dir):
        entries = read_log(path)
        if not any(entry.kind == Kind.SESSION_ENDED for entry in entries):
            skipped.append(f"{path.name}: the session is not finished; resume it to include it")
            continue
        try:
            row = row_from_log(entries)
        except VahrError as err:
            skipped.append(f"{path.name}: {err}")
            continue
        if row.task_time_s == 0:
            skipped.append(f"{path.name}: no finished task")
            continue
        rows.append(row)
    if not rows:
        why = f" ({'; '.join(skipped)})" if skipped else ""
        raise VahrError(f"no finished sessions under {log_dir}{why}")
    return rows, skipped


def session_summary(entries: list[LogEntry]) -> dict[str, object]:
    """One session's header, measured times and the judge's verdict, for sessions.json."""
    header = session_header(entries)
    summary: dict[str, object] = {
        key: header.get(key)
        for key in ("session", "participant", "method", "trial", "seed", "simulated")
    }
    summary["finished"] = any(entry.kind == Kind.SESSION_ENDED for entry in entries)
    summary["times"] = measure_session(entries).to_json()
    if isinstance(header.get("plan"), dict):
        plan = Plan.from_json(header["plan"])  # type: ignore[arg-type]
        summary["plan"] = plan.to_json()
        summary["verdict"] = judge_session(entries, plan).to_json()
    return summary
