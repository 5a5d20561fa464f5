"""`robot-agent speak "TEXT" --out FILE.wav`: render text with the robot's voice."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.errors import VahrError
from vahr.speech.errors import SpeechError
from vahr.speech.tts import DEFAULT_VOICE

if TYPE_CHECKING:
    import argparse


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("text", help="what to say")
    parser.add_argument("--out", required=True, type=Path, help="WAV file to write (16 kHz mono)")
    parser.add_argument(
        "--voice",
        default=DEFAULT_VOICE,
        help=f"espeak-ng voice (default: {DEFAULT_VOICE}); or polly:VOICE, gtts[:LANG]",
    )
    parser.add_argument("--json", action="store_true", help="print the file and duration as JSON")


def run(args: argparse.Namespace) -> int:
    from vahr.speech.tts import make_synthesizer

    spec = args.voice if ":" in args.voice or args.voice in ("polly", "gtts") else None
    try:
        synthesizer = make_synthesizer(spec or f"espeak:{args.voice}")
        audio = synthesizer.synthesize(args.text)
    except SpeechError as err:
        raise VahrError(str(err)) from err
    out: Path = args.out
    try:
        out.write_bytes(audio.to_wav())
    except OSError as err:
        raise VahrError(f"--out {out}: {err.strerror}") from err
    if args.json:
        print(json.dumps({"out": str(out), "seconds": round(audio.seconds, 3)}))
    else:
        print(out)
    return 0
