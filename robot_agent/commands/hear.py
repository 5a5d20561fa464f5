"""`robot-agent hear FILE.wav [--json]`: recognize and interpret an assistant's answer."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.errors import VahrError
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    import argparse


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, help="WAV file (any rate and channels; - for stdin)")
    parser.add_argument(
        "--json", action="store_true", help='print {"text", "intent", "confidence"}'
    )
    parser.add_argument(
        "--answers",
        type=Path,
        default=None,
        help="weather answers file (default: the bundled weather_answers.yaml)",
    )


def run(args: argparse.Namespace) -> int:
    import sys

    from robot_agent.voice.understanding import offline_understanding
    from vahr.speech.audio import Audio

    path: Path = args.file
    try:
        data = sys.stdin.buffer.read() if str(path) == "-" else path.read_bytes()
    except OSError as err:
        raise VahrError(f"{path}: {err.strerror}") from err
    try:
        heard = offline_understanding(args.answers).hear(Audio.from_wav(data))
    except SpeechError as err:
        raise VahrError(f"{path}: {err}") from err
    if args.json:
        print(
            json.dumps({"text": heard.text, "intent": heard.intent, "confidence": heard.confidence})
        )
    else:
        print(f"{heard.intent}\t{heard.confidence:.3f}\t{heard.text}")
    return 0
