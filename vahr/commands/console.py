"""`vahr console`: talk to the running system turn by turn, optionally hearing replies."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import argparse
    from collections.abc import Iterator

PROMPT = "you> "


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--api", help="the running system's API (default $VAHR_API or :8180)")
    parser.add_argument(
        "--speak",
        action="store_true",
        help="speak replies, and what the assistant announces unprompted, with espeak-ng",
    )
    parser.add_argument(
        "--locale",
        default="en-US",
        help="the language spoken: en-US (default) or de-DE; the system must run in it",
    )


def run(args: argparse.Namespace) -> int:
    from vahr.assistant.localized import supported
    from vahr.plumbing.client import call, default_api

    supported(args.locale)
    api = args.api or default_api()
    call(api, "GET", "/vahr/health")  # fail now, with one line, if nothing runs
    interactive = sys.stdin.isatty()
    if interactive:
        print("Talk to the robot fleet (e.g. 'Alexa, open robot fleet'); Ctrl-D ends.")
    feed = _announcements(api, speak=args.speak) if args.speak else None
    try:
        _converse(api, args, interactive)
    finally:
        if feed is not None:
            feed.stop()
    return 0


def _announcements(api: str, *, speak: bool) -> Any:
    """Say each new announcement (a robot stuck, failed, offline) as the Echo would."""
    from vahr.plumbing.announcement_feed import AnnouncementFeed
    from vahr.speech.speaker import speak as say_aloud

    def tell(announcement: dict[str, Any]) -> None:
        print(f"\nalexa> {announcement['speech']}  [announcement: {announcement['kind']}]")
        if speak:
            say_aloud(announcement["speech"])

    return AnnouncementFeed(api, tell).start()


def _converse(api: str, args: argparse.Namespace, interactive: bool) -> None:
    from vahr.errors import VahrError
    from vahr.plumbing.client import say

    for line in _lines(interactive):
        utterance = line.strip()
        if not utterance:
            continue
        try:
            turn = say(api, utterance, args.locale)
        except VahrError as err:
            print(f"error: {err}", file=sys.stderr)
            continue
        speech = turn["speech"] or "(no answer)"
        print(
            f"alexa> {speech}  [{turn['intent'] or turn['request_type']}, "
            f"{turn['latency_ms']:.0f} ms]"
        )
        if args.speak and turn["speech"]:
            from vahr.speech.speaker import speak, voice_for

            speak(turn["speech"], voice=voice_for(args.locale))


def _lines(interactive: bool) -> Iterator[str]:
    while True:
        try:
            line = input(PROMPT) if interactive else sys.stdin.readline()
        except EOFError:
            return
        if not interactive and not line:
            return
        yield line
