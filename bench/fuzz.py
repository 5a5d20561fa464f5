"""Property-based fuzzing at scale: every fuzz test of tests/fuzz/ with the `bench`
hypothesis profile (at least 10,000 generated inputs per boundary, derandomized).

The tests hold the properties (no crash or hang, a rejection naming the field, nothing
changed by a rejected input, still serving afterwards); this script runs them with the
large budget and tabulates what each boundary took. A failing property fails the run.
Run: `.venv/bin/python bench/fuzz.py [-k EXPRESSION]` (about 15-20 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import write_section

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("-k", default="", help="only the fuzz tests matching this expression")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "tally.json"
        env = {**os.environ, "VAHR_FUZZ_PROFILE": "bench", "VAHR_FUZZ_REPORT": str(report)}
        command = [
            sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:logging",
            "--timeout", "0", "tests/fuzz",
        ]  # fmt: skip
        if args.k:
            command += ["-k", args.k]
        started = time.monotonic()
        done = subprocess.run(command, cwd=ROOT, env=env, check=False)
        elapsed = time.monotonic() - started
        tally = json.loads(report.read_text()) if report.exists() else {}
    rows = [
        f"| {boundary} | {counts['tried']:,} | {counts['accepted']:,} | {counts['rejected']:,} "
        f"| {'0' if done.returncode == 0 else 'see run'} |"
        for boundary, counts in tally.items()
    ]
    only = f" Only the tests matching `-k {args.k}` ran." if args.k else ""
    body = f"""
Every boundary that takes outside input, fed by hypothesis (`bench` profile, derandomized)
through its real entry point; {elapsed / 60:.1f} minutes in one run. Accepted inputs did what
they asked; rejected ones were refused with a reason naming the field (or AWS's code) and
changed nothing; a crash, hang or wrong answer would fail the run. pytest exit code:
{done.returncode}.{only}

| boundary | inputs | accepted | rejected | crashes |
| --- | --- | --- | --- | --- |
{chr(10).join(rows)}
"""
    write_section("fuzz", "Fuzzing every outside-input boundary", body)
    if done.returncode != 0:
        raise SystemExit(done.returncode)


if __name__ == "__main__":
    main()
