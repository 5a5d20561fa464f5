"""`vahr report`: the paper's tables and figures from a results CSV or from session logs.

`vahr report FILE.csv --out DIR` reads one row per participant, method and trial;
`vahr report --from-log DIR --out DIR` measures the rows from the session logs under DIR.
Both write DIR/report.json, DIR/report.md, DIR/results.csv and the figures (PNG and SVG);
from logs also
DIR/sessions.json (each session's plan, measured times and the judge's verdict).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.errors import VahrError

if TYPE_CHECKING:
    import argparse


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("csv", nargs="?", type=Path, help="results CSV (one row per run)")
    parser.add_argument(
        "--from-log",
        type=Path,
        metavar="DIR",
        help="measure the results from the session logs under DIR",
    )
    parser.add_argument("--out", type=Path, required=True, help="directory for the report")
    parser.add_argument("--json", action="store_true", help="print report.json to stdout")


def run(args: argparse.Namespace) -> int:
    from vahr.experiment.figures import figure_names
    from vahr.experiment.report import write_report
    from vahr.experiment.results import read_csv, rows_from_logs

    if (args.csv is None) == (args.from_log is None):
        raise VahrError("give either a results CSV or --from-log DIR")
    simulated = False
    if args.csv is not None:
        rows, source = read_csv(args.csv), str(args.csv)
    else:
        from vahr.experiment.eventlog import Kind, find_logs, read_log

        rows, skipped = rows_from_logs(args.from_log)
        for reason in skipped:
            print(f"skipped {reason}", file=sys.stderr)
        source = str(args.from_log)
        simulated = any(
            entry.data.get("simulated")
            for path in find_logs(args.from_log)
            for entry in read_log(path)[:1]
            if entry.kind == Kind.SESSION_STARTED
        )
    report = write_report(rows, args.out, source=source, simulated=simulated)
    files = ["report.json", "report.md", "results.csv", *figure_names(report)]
    if args.from_log is not None:
        from vahr.experiment.eventlog import find_logs, read_log
        from vahr.experiment.results import session_summary

        sessions = [session_summary(read_log(path)) for path in find_logs(args.from_log)]
        (args.out / "sessions.json").write_text(json.dumps(sessions, indent=2) + "\n")
        files.append("sessions.json")
    if args.json:
        print(json.dumps(report))
    else:
        print(f"report of {report['rows']} runs written to {args.out}: {', '.join(files)}")
    return 0
