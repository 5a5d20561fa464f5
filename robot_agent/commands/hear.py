"""`robot-agent hear`: recognize and interpret an assistant's answer, and measure how well.

- `hear FILE.wav [--json]`: what was heard, the intent, the confidence, the phrases that
  decided it and, when it is unknown, why;
- `hear --make-eval-set DIR [--phrasings FILE]`: speak the evaluation set (or another
  phrasings file) into DIR, the same bytes on every run;
- `hear --eval DIR [--json]`: hear every clip of DIR and print right, wrong-intent and
  fallback (unknown) rates per condition and intent.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.errors import VahrError
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    import argparse

    from robot_agent.voice.port import Heard


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "file", type=Path, nargs="?", help="WAV file (any rate and channels; - for stdin)"
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help='print {"text", "intent", "confidence", "evidence", "reason"} (with --eval: '
        "the rates)",
    )
    parser.add_argument(
        "--answers",
        type=Path,
        default=None,
        help="weather answers file (default: the bundled weather_answers.yaml)",
    )
    parser.add_argument(
        "--eval", type=Path, metavar="DIR", help="score every clip of a set made by --make-eval-set"
    )
    parser.add_argument(
        "--make-eval-set", type=Path, metavar="DIR", help="speak the evaluation set into DIR"
    )
    parser.add_argument(
        "--phrasings",
        type=Path,
        default=None,
        help="with --make-eval-set: the phrasings file (default: the bundled evaluation set)",
    )


def run(args: argparse.Namespace) -> int:
    chosen = [name for name in ("file", "eval", "make_eval_set") if getattr(args, name)]
    if len(chosen) != 1:
        raise VahrError("give one of FILE, --eval DIR or --make-eval-set DIR")
    if args.make_eval_set:
        return _make_eval_set(args)
    if args.eval:
        return _evaluate(args)
    return _hear_file(args)


def heard_json(heard: Heard) -> dict[str, object]:
    return {
        "text": heard.text,
        "intent": heard.intent,
        "confidence": heard.confidence,
        "evidence": list(heard.evidence),
        "reason": heard.reason,
    }


def _hear_file(args: argparse.Namespace) -> int:
    import sys

    from robot_agent.voice.hearing import offline_hearing
    from vahr.speech.audio import Audio

    path: Path = args.file
    try:
        data = sys.stdin.buffer.read() if str(path) == "-" else path.read_bytes()
    except OSError as err:
        raise VahrError(f"{path}: {err.strerror}") from err
    try:
        heard = offline_hearing(args.answers).hear(Audio.from_wav(data))
    except SpeechError as err:
        raise VahrError(f"{path}: {err}") from err
    if args.json:
        print(json.dumps(heard_json(heard)))
    else:
        why = ", ".join(heard.evidence) if heard.intent != "unknown" else heard.reason
        print(f"{heard.intent}\t{heard.confidence:.3f}\t{heard.text}\t({why})")
    return 0


def _make_eval_set(args: argparse.Namespace) -> int:
    from robot_agent.voice.evaluation import (
        EVALUATION_SET,
        Phrasings,
        manifest_json,
        render,
        synthesizer_for_voice,
    )

    source: Path = args.phrasings or EVALUATION_SET
    phrasings = Phrasings.load(source)
    directory: Path = args.make_eval_set
    try:
        directory.mkdir(parents=True, exist_ok=True)
        manifest = render(phrasings, directory, synthesizer_for_voice, source=source.name)
    except SpeechError as err:
        raise VahrError(str(err)) from err
    except OSError as err:
        raise VahrError(f"{directory}: {err.strerror}") from err
    print(manifest_json(manifest, directory))
    return 0


def _evaluate(args: argparse.Namespace) -> int:
    import time

    from robot_agent.voice.evaluation import score
    from robot_agent.voice.hearing import offline_hearing

    try:
        hearing = offline_hearing(args.answers)
        report = score(args.eval, hearing.hear, time.perf_counter)
    except SpeechError as err:
        raise VahrError(str(err)) from err
    if args.json:
        print(json.dumps(report.to_json()))
        return 0
    print(report.table())
    print(f"unrelated speech accepted as an answer: {report.unrelated().rate('wrong'):.1%}")
    for miss in report.misses:
        print(f"  {miss['file']}: said {miss['said']!r}, heard {miss['heard']!r} -> "
              f"{miss['intent']} ({miss['reason'] or 'decided'})")  # fmt: skip
    return 0
