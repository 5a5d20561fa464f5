"""`vahr console`: talk to the running system turn by turn, optionally hearing replies."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import argparse
    from collections.abc import Iterator

PROMPT = "you> "


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--api", help="the running system's API (default $VAHR_API or :8180)")
    parser.add_argument("--speak", action="store_true", help="speak replies with espeak-ng")


def run(args: argparse.Namespace) -> int:
    from vahr.errors import VahrError
    from vahr.local.client import call, default_api, say

    api = args.api or default_api()
    call(api, "GET", "/vahr/health")  # fail now, with one line, if nothing runs
    interactive = sys.stdin.isatty()
    if interactive:
        print("Talk to the robot fleet (e.g. 'Alexa, open robot fleet'); Ctrl-D ends.")
    for line in _lines(interactive):
        utterance = line.strip()
        if not utterance:
            continue
        try:
            turn = say(api, utterance)
        except VahrError as err:
            print(f"error: {err}", file=sys.stderr)
            continue
        speech = turn["speech"] or "(no answer)"
        print(
            f"alexa> {speech}  [{turn['intent'] or turn['request_type']}, "
            f"{turn['latency_ms']:.0f} ms]"
        )
        if args.speak and turn["speech"]:
            from vahr.local.speaker import speak

            speak(turn["speech"])
    return 0


def _lines(interactive: bool) -> Iterator[str]:
    while True:
        try:
            line = input(PROMPT) if interactive else sys.stdin.readline()
        except EOFError:
            return
        if not interactive and not line:
            return
        yield line
