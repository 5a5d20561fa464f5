"""Benchmark: a whole simulated study (`vahr rehearse`) against its 10-minute target.

Runs `vahr rehearse --participants N --trials T` (default 10 x 2, the paper's study: 40
sessions) on a stack of its own, as a user would, and reports the wall time (target: under
600 s), the time per session and the study-time to wall-time ratio it achieved, with the
rehearsal's results beside the paper's Table II.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _results import write_section  # noqa: E402

from vahr.experiment.paper import render_comparison  # noqa: E402

TARGET_S = 600.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--participants", type=int, default=10)
    parser.add_argument("--trials", type=int, default=2)
    parser.add_argument("--speed-factor", type=float, default=30.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-rehearsal-") as folder:
        out = Path(folder) / "rehearsal"
        started = time.perf_counter()
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "vahr.cli",
                "rehearse",
                "--participants",
                str(args.participants),
                "--trials",
                str(args.trials),
                "--speed-factor",
                f"{args.speed_factor:g}",
                "--out",
                str(out),
            ],
            capture_output=True,
            text=True,
            check=False,
        )
        wall_s = time.perf_counter() - started
        if done.returncode != 0:
            print(done.stderr[-2000:], file=sys.stderr)
            return 1
        report = json.loads((out / "report.json").read_text())
    sessions = args.participants * args.trials * 2
    study_s = sum(
        report["objective"]["time_taken"]["means"][m] * report["objective"]["time_taken"]["n"][m]
        for m in report["methods"]
    )
    body = f"""
`vahr rehearse --participants {args.participants} --trials {args.trials}` on a stack of its
own at x{args.speed_factor:g} ({sessions} sessions, both methods), start to finish.

| measure | value | target |
| --- | ---: | --- |
| wall time of the whole study | {wall_s:.0f} s | under {TARGET_S:.0f} s |
| wall time per session (stack start included) | {wall_s / sessions:.1f} s | |
| study time in the tasks, all sessions | {study_s:.0f} s | |
| study seconds per wall second | {study_s / wall_s:.1f} | |

Target met: {"yes" if wall_s < TARGET_S else "no"}. The rehearsal's results (simulated
participants), beside the paper's Table II:

{render_comparison(report["paper_comparison"])}
"""
    write_section("rehearsal", "A simulated study, start to finish", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
