"""Benchmark: the experiment's event log and scoring, as a session and a report use them.

- append latency: one event committed with WAL and `synchronous=FULL` (what makes the log
  crash-safe), beside `synchronous=NORMAL` for comparison, on this machine's disk;
- scoring: judging and measuring a long session log (thousands of robot progress events);
- the report: 100 runs (means, one-way ANOVAs, the within-subjects analysis) without and
  with the three figures.
"""

from __future__ import annotations

import random
import sys
import tempfile
import time
from datetime import UTC, datetime, timedelta
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _results import median, percentile, write_section  # noqa: E402

from vahr.domain import load_fleet
from vahr.experiment.eventlog import EventLog, Kind  # noqa: E402
from vahr.experiment.judge import judge_session  # noqa: E402
from vahr.experiment.measure import measure_session  # noqa: E402
from vahr.experiment.report import build_report, write_report  # noqa: E402
from vahr.experiment.results import ResultRow  # noqa: E402
from vahr.experiment.tasks import draw_plan  # noqa: E402
from vahr.experiment.tlx import ITEMS, TlxAnswers  # noqa: E402


def append_ms(folder: Path, synchronous: str, count: int = 400) -> list[float]:
    log = EventLog.open(folder / f"append-{synchronous}.sqlite")
    log._connection.execute(f"PRAGMA synchronous={synchronous}")
    samples = []
    for n in range(count):
        start = time.perf_counter()
        log.append(Kind.ROBOT_EVENT, {"event": "progress", "thing": "placebot1", "n": n})
        samples.append((time.perf_counter() - start) * 1000)
    log.close()
    return samples


def long_session(folder: Path, progress_events: int) -> tuple[list, object]:
    fleet = load_fleet()
    plan = draw_plan(fleet, 1)
    t0 = datetime(2026, 1, 1, tzinfo=UTC)
    log = EventLog.open(folder / "long.sqlite")
    log._connection.execute("PRAGMA synchronous=OFF")  # building the fixture only
    log.append(
        Kind.SESSION_STARTED,
        {"participant": "B", "method": "vahr", "trial": 1, "plan": plan.to_json()},
        at=t0,
    )
    second = 0.0
    for task in ("I", "II", "III"):
        log.append(Kind.TASK_STARTED, {"task": task}, task=task, at=t0 + timedelta(seconds=second))
        for n in range(progress_events // 3):
            second += 0.05
            if n % 50 == 0:
                log.append(
                    Kind.INTERACTION_STARTED,
                    {"id": f"{task}{n}"},
                    at=t0 + timedelta(seconds=second),
                )
                log.append(
                    Kind.INTERACTION_ENDED,
                    {"id": f"{task}{n}", "commands": ["c"]},
                    at=t0 + timedelta(seconds=second + 2),
                )
            log.append(
                Kind.ROBOT_EVENT,
                {"event": "progress", "thing": "placebot1"},
                task=task,
                at=t0 + timedelta(seconds=second),
            )
        for thing, zone in plan.goal(task).zones.items():
            second += 1
            log.append(
                Kind.ROBOT_EVENT,
                {"event": "delivered", "thing": thing, "zone": zone},
                task=task,
                at=t0 + timedelta(seconds=second),
            )
        log.append(Kind.TASK_ENDED, {"task": task}, task=task, at=t0 + timedelta(seconds=second))
    entries = log.entries()
    log.close()
    return entries, plan


def rows(count: int) -> list[ResultRow]:
    rng = random.Random(3)
    return [
        ResultRow(
            f"P{n // 6}",
            "vahr" if n % 2 else "keyboard",
            n % 3 + 1,
            rng.uniform(80, 200),
            rng.uniform(40, 160),
            rng.uniform(200, 300),
            rng.randint(0, 12),
            TlxAnswers(**{i: rng.randint(1, 21) for i in ITEMS}),
        )
        for n in range(count)
    ]


def main() -> None:
    with tempfile.TemporaryDirectory(dir=Path.cwd()) as tmp:
        folder = Path(tmp)
        full = append_ms(folder, "FULL")
        normal = append_ms(folder, "NORMAL")
        entries, plan = long_session(folder, 9000)
        start = time.perf_counter()
        verdict = judge_session(entries, plan)  # type: ignore[arg-type]
        times = measure_session(entries)
        scoring_ms = (time.perf_counter() - start) * 1000
        assert verdict.task_tally.successes == 3, verdict.to_json()
        data = rows(100)
        start = time.perf_counter()
        # The report's first analysis pays these imports once.
        import scipy.stats  # noqa: F401
        import statsmodels.stats.anova  # noqa: F401
        import statsmodels.stats.weightstats  # noqa: F401

        scipy_ms = (time.perf_counter() - start) * 1000
        start = time.perf_counter()
        build_report(data)
        report_ms = (time.perf_counter() - start) * 1000
        start = time.perf_counter()
        write_report(data, folder / "report")
        figures_s = time.perf_counter() - start
    table = [
        (
            "append one event, WAL + `synchronous=FULL` (crash-safe, used)",
            f"median {median(full):.2f} ms, p99 {percentile(full, 99):.2f} ms",
        ),
        (
            "append one event, WAL + `synchronous=NORMAL` (for comparison)",
            f"median {median(normal):.2f} ms, p99 {percentile(normal, 99):.2f} ms",
        ),
        (
            f"judge and measure a session log of {len(entries)} events",
            f"{scoring_ms:.0f} ms (IE {times.interaction_s:.0f} s of T {times.time_taken_s:.0f} s)",
        ),
        (
            "first import of scipy.stats and statsmodels (paid once per report)",
            f"{scipy_ms:.0f} ms",
        ),
        (
            "report of 100 runs: means, 15 one-way ANOVAs and the within-subjects analysis",
            f"{report_ms:.0f} ms",
        ),
        ("report of 100 runs with report.md, results.csv and 3 PNG figures", f"{figures_s:.1f} s"),
    ]
    body = "| what | result |\n| --- | --- |\n"
    body += "".join(f"| {what} | {result} |\n" for what, result in table)
    body += (
        "\nA session logs a few hundred events (progress events dominate: one per robot per\n"
        "simulated second), so even the crash-safe commit keeps the recorder far ahead of the\n"
        "robots.\n"
    )
    write_section("experiment_log", "Experiment: event log, scoring and report", body)


if __name__ == "__main__":
    main()
