"""The soak: 100 swarm robots and 2 robot-agent processes on `vahr up` for 30 minutes,
under a steady, seeded mix of skill and console commands, while mosquitto is killed,
robot-agents are killed, the shadow service is paused and connections are cut.

The harness is `tests/support/soak.py` (the test suite runs it for 2 minutes). Reported
from the robots' own records and the shadows: commands executed once, reported failed or
cancelled with a reason, lost (target 0), run twice (target 0); shadows that did not
converge; the largest RSS of each process against its bound; the skill's answers against
Alexa's 8 s; the longest recovery after a broker restart.
Run: `nice .venv/bin/python bench/soak.py [--minutes 30] [--seed 16]`.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path

from _results import percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.support.soak import (  # noqa: E402
    FAULTS,
    MEMORY_BOUNDS_MB,
    SKILL_DEADLINE_S,
    SoakConfig,
    SoakReport,
    run_soak,
    summary,
)


def body(report: SoakReport) -> str:
    v = report.verdict
    cfg = report.config
    latencies = [t.latency_s for t in report.turns if not t.error]
    reported = ", ".join(f"{count} {kind}" for kind, count in sorted(v.reported.items()))
    lines = [
        f"{report.elapsed_s / 60:.1f} minutes of load (seed {cfg.seed}); {cfg.swarm_size} swarm "
        f"robots and 2 robot-agent processes on `vahr up`; a console command every "
        f"{cfg.console_interval_s:g} s (one in ten as desired state), an utterance every "
        f"{cfg.skill_interval_s:g} s, a fault every {cfg.fault_interval_s:g} s; simulated "
        f"time {cfg.sim_speed_factor:g}x.",
        "",
        "| figure | value | target |",
        "| --- | --- | --- |",
        f"| commands owed to a robot (sent, times robots addressed) | {v.owed} | - |",
        f"| executed once | {v.executed} | - |",
        f"| reported failed, cancelled or rejected, with a reason | {reported or 0} "
        f"({v.reported_without_reason} without a reason) | - |",
        f"| written as desired state and replaced by a later one before the robot read it "
        f"(last writer wins) | {v.replaced_in_desired} | - |",
        f"| lost | {len(v.lost)} | 0 |",
        f"| run twice | {len(v.run_twice)} | 0 |",
        f"| publishes refused at the source (the sender was told) | {v.refused_at_source} | - |",
        f"| of those, run anyway | {len(v.ran_after_refusal)} | 0 |",
        f"| ids run that no sender sent | {len(v.unknown)} | 0 |",
        f"| shadows that did not converge (of {report.shadows_checked}) | "
        f"{len(report.unconverged)} | 0 |",
        f"| skill turns; p50, p99, max latency | {len(report.turns)}; "
        + (
            f"{statistics.median(latencies):.2f} s, {percentile(latencies, 99):.2f} s, "
            f"{max(latencies):.2f} s"
            if latencies
            else "-"
        )
        + f" | every one under {SKILL_DEADLINE_S:g} s |",
        f"| turns over {SKILL_DEADLINE_S:g} s, without speech or unanswered | "
        f"{len(report.slow_or_invalid_turns)} | 0 |",
        f"| crashes | {len(report.crashes)} | 0 |",
        "| longest recovery after a broker restart (broker back to both agents and a swarm "
        f"robot answering a ping) | {_seconds(report.longest_recovery_s)} | - |",
        "",
        "| fault | tried | survived |",
        "| --- | --- | --- |",
    ]
    for kind in FAULTS:
        of_kind = [f for f in report.faults if f.kind == kind]
        survived = sum(1 for f in of_kind if f.survived)
        lines.append(f"| {kind} | {len(of_kind)} | {survived} |")
    lines += ["", "| process | RSS at start | largest RSS | bound |", "| --- | --- | --- | --- |"]
    for role, (first, largest) in sorted(report.rss_mb.items()):
        lines.append(
            f"| {role} | {first:.0f} MB | {largest:.0f} MB | {MEMORY_BOUNDS_MB[role]} MB |"
        )
    problems = (
        [f"lost: {x}" for x in v.lost[:10]]
        + [f"run twice: {x}" for x in v.run_twice[:10]]
        + [f"run after refusal: {x}" for x in v.ran_after_refusal[:10]]
        + [f"unknown id: {x}" for x in v.unknown[:10]]
        + [f"shadow: {x}" for x in report.unconverged[:10]]
        + [f"crash: {x}" for x in report.crashes[:10]]
        + [f"memory: {x}" for x in report.memory_over_bound]
        + [
            f"not recovered: {f.kind} at {f.at_s:.0f} s: {f.detail}"
            for f in report.faults
            if not f.survived
        ]
    )
    if problems:
        lines += ["", "Problems seen:", "", *(f"- {p}" for p in problems)]
    return "\n".join(lines)


def _seconds(value: float | None) -> str:
    return f"{value:.2f} s" if value is not None else "-"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--seed", type=int, default=16)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="vahr-soak-") as work:
        report = run_soak(
            SoakConfig(duration_s=args.minutes * 60, work_dir=Path(work), seed=args.seed)
        )
    print(json.dumps(summary(report), default=str))
    write_section("soak", "Soak: faults and load together", body(report))
    v = report.verdict
    failed = v.lost or v.run_twice or report.unconverged or report.crashes
    return 1 if failed or report.slow_or_invalid_turns or report.memory_over_bound else 0


if __name__ == "__main__":
    raise SystemExit(main())
