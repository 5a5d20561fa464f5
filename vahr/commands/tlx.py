"""`vahr tlx`: record a participant's NASA-TLX answers (and confidence, trust) for a session.

Levels are 1-21 (1 -> 0 %, 21 -> 100 %). Items not given as flags are asked for on the
terminal; without a terminal every item must be given. The answers are appended to the
session's event log; entering them again records a new answer that replaces the old one in
the report (the log itself is never edited).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.errors import VahrError

if TYPE_CHECKING:
    import argparse

DEFAULT_LOG_DIR = Path(".state") / "experiment"


def configure(parser: argparse.ArgumentParser) -> None:
    from vahr.experiment.tlx import ITEMS, QUESTIONS

    parser.add_argument("--participant", required=True)
    parser.add_argument("--method", required=True, choices=["vahr", "keyboard"])
    parser.add_argument("--trial", required=True, type=int)
    parser.add_argument(
        "--log-dir",
        type=Path,
        default=DEFAULT_LOG_DIR,
        help=f"where session logs live (default: {DEFAULT_LOG_DIR})",
    )
    for item in ITEMS:
        parser.add_argument(f"--{item}", type=int, metavar="LEVEL", help=f"1-21: {QUESTIONS[item]}")
    parser.add_argument("--json", action="store_true", help="print the stored answers as JSON")


def _ask(item: str, question: str) -> int:
    from vahr.experiment.tlx import check_level

    while True:
        answer = input(f"{question} [1-21]: ").strip()
        try:
            return check_level(item, answer)
        except ValueError as err:
            print(err, file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    from vahr.experiment.eventlog import EventLog, Kind, session_file
    from vahr.experiment.tlx import ITEMS, QUESTIONS, TlxAnswers

    path = session_file(args.log_dir, args.participant, args.method, args.trial)
    if not path.is_file():
        raise VahrError(f"no session log at {path}; run `vahr experiment` for this session first")
    given = {item: getattr(args, item) for item in ITEMS if getattr(args, item) is not None}
    missing = [item for item in ITEMS if item not in given]
    if missing and not sys.stdin.isatty():
        raise VahrError(f"missing answers for {', '.join('--' + m for m in missing)}")
    for item in missing:
        given[item] = _ask(item, QUESTIONS[item])
    try:
        answers = TlxAnswers.from_mapping(given)
    except ValueError as err:
        raise VahrError(str(err)) from None
    with EventLog.open(path, create=False) as log:
        log.append(
            Kind.TLX,
            {
                "levels": answers.levels(),
                "percent": answers.percents(),
                "raw_tlx": answers.raw_tlx(),
            },
        )
    if args.json:
        print(
            json.dumps(
                {
                    "session": path.stem,
                    "levels": answers.levels(),
                    "percent": answers.percents(),
                    "raw_tlx": answers.raw_tlx(),
                }
            )
        )
    else:
        print(f"recorded NASA-TLX for {path.stem}: raw TLX {answers.raw_tlx():.1f} %")
    return 0
