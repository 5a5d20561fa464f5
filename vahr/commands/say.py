"""`vahr say "UTTERANCE"`: speak to the running system as a person speaks to Alexa."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import argparse


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("utterance", help='e.g. "Alexa, ask robot fleet to send robot one to A"')
    parser.add_argument("--api", help="the running system's API (default $VAHR_API or :8180)")
    parser.add_argument("--json", action="store_true", help="print the whole turn as JSON")
    parser.add_argument("--speak", action="store_true", help="also speak the reply (espeak-ng)")
    parser.add_argument(
        "--user",
        metavar="ID",
        help="speak as this Alexa account (its userId, as in the users file of vahr up --users)",
    )
    parser.add_argument(
        "--person",
        metavar="ID",
        help="speak as a voice Alexa recognised (a personId: preferred over --user for roles)",
    )
    parser.add_argument(
        "--locale",
        default="en-US",
        help="the language spoken: en-US (default) or de-DE; the system must run in it "
        "(vahr up --locale)",
    )


def run(args: argparse.Namespace) -> int:
    from vahr.domain.locale import LocaleError, check_locale
    from vahr.domain.people import MAX_ID_CHARS, valid_person_id
    from vahr.errors import VahrError
    from vahr.plumbing.client import default_api, say

    # Checked here rather than by `vahr.assistant.localized.supported`: importing the
    # assistant loads its NLU's libraries, half of this command's start.
    try:
        check_locale(args.locale)
    except LocaleError as err:
        raise VahrError(str(err)) from err
    if not args.utterance.strip():
        raise VahrError("the utterance is empty")
    for flag in ("user", "person"):
        value = getattr(args, flag)
        if value is not None and not valid_person_id(value):
            raise VahrError(
                f"--{flag} {value!r}: an Alexa id is 1 to {MAX_ID_CHARS} printable characters"
            )
    turn = say(
        args.api or default_api(), args.utterance, args.locale, user=args.user, person=args.person
    )
    if args.json:
        print(json.dumps(turn))
    else:
        print(turn["speech"] or "(no answer)")
    if args.speak and turn.get("speech"):
        from vahr.speech.speaker import speak, voice_for

        speak(turn["speech"], voice=voice_for(args.locale))
    return 0
