"""What acting on a stop either ear hears costs and gains: push-to-talk's decisions on the
development voices with and without the rule, in one run.

The station acts on a stop that either recognizer hears clearly (`vahr.assistant.nbest.
stop_heard`) even when the other heard something else, and asks Whisper about every clip
pocketsphinx took for speech (not only those whose best transcript read as a request).
This script hears the NLU's development set (written blind, never tuned on) in the
development voices of `bench/station_hearing.py` (its clips and transcripts are shared and
cached), decides each clip as the station does with the rule and as it did without it,
and counts the stops acted on: said (right) and not said (wrong stops), and every wrong
action. Run: `.venv/bin/python bench/wrong_stops.py`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from _results import write_section
from station_hearing import (
    DEVELOPMENT_VOICES,
    Clip,
    Reader,
    decide,
    hear,
    hear_again,
)

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet, outcome  # noqa: E402
from vahr.assistant.nbest import (  # noqa: E402
    STOP_INTENT,
    Weighing,
    agreement,
    disputed,
    stop_heard,
)
from vahr.assistant.nlu import InteractionModel, Understanding  # noqa: E402
from vahr.domain.fleet import load_fleet  # noqa: E402
from vahr.domain.invocation import FALLBACK_INTENT  # noqa: E402
from vahr.speech.whisper_stt import WhisperTranscriber  # noqa: E402
from vahr.station.vocabulary import command_recognizer, whisper_prompt  # noqa: E402


def station_decides(
    clip: Clip, second: str, read: Reader, weighing: Weighing, *, stop_rule: bool
) -> Understanding:
    """The station's decision with both ears (`PushToTalk.weigh`), with or without the
    rule; without it, as before: Whisper only when the best transcript reads as a request."""
    best = clip.recognition.text if clip.recognition.accepted else ""
    if not second or not best:
        return decide(clip, read, weighing)
    if not stop_rule and read(best).intent == FALLBACK_INTENT:
        return decide(clip, read, weighing)
    both = agreement(read.model, second, best, read)
    if both is not None:
        return both.understanding
    decided = decide(clip, read, weighing)
    if stop_rule and decided.intent != STOP_INTENT:
        stop = stop_heard(read.model, second, read)
        if stop is not None:
            return stop.understanding
    return disputed(read.model, decided, read(second))


def count(
    clips: list[Clip], seconds: dict[int, str], read: Reader, *, stop_rule: bool
) -> dict[str, int]:
    counts = {"stops said": 0, "acted on": 0, "wrong stops": 0, "wrong actions": 0}
    for n, clip in enumerate(clips):
        got = station_decides(clip, seconds.get(n, ""), read, Weighing(), stop_rule=stop_rule)
        said_stop = clip.item.intent == STOP_INTENT
        counts["stops said"] += said_stop
        counts["acted on"] += said_stop and got.intent == STOP_INTENT
        counts["wrong stops"] += (not said_stop) and got.intent == STOP_INTENT
        counts["wrong actions"] += outcome(read.model, clip.item, got) == "wrong"
    return counts


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--voices",
        nargs="+",
        default=list(DEVELOPMENT_VOICES),
        choices=DEVELOPMENT_VOICES,
        help="the development voices to hear (default: all)",
    )
    voices = parser.parse_args().voices
    model = InteractionModel.load()
    read = Reader(model)
    recognizer = command_recognizer()
    whisper = WhisperTranscriber(whisper_prompt(load_fleet()))
    development_set = LabelledSet.load(DEVELOPMENT_SET)
    rows = []
    totals = {
        rule: dict.fromkeys(("stops said", "acted on", "wrong stops", "wrong actions"), 0)
        for rule in (False, True)
    }
    clips_heard = 0
    for voice in voices:
        clips = hear(recognizer, [(item, voice) for item in development_set.items()])
        seconds = {n: text for n, (text, _) in hear_again(whisper, clips).items()}
        clips_heard += len(clips)
        for rule in (False, True):
            counts = count(clips, seconds, read, stop_rule=rule)
            for key, value in counts.items():
                totals[rule][key] += value
            rows.append(_row(f"{voice}, {'with' if rule else 'without'} the rule", counts))
    rows += [
        _row(f"together, {'with' if rule else 'without'} the rule", totals[rule])
        for rule in (False, True)
    ]
    table = "\n".join(rows)
    requests = [i for i in development_set.items() if i.intent != FALLBACK_INTENT]
    stops = sum(i.intent == STOP_INTENT for i in requests)
    body = f"""
{clips_heard} clips: the {len(requests)} requests ({stops} of them stops) and
{len(development_set.items()) - len(requests)} out-of-domain sentences of
{DEVELOPMENT_SET.name}, spoken by {len(voices)} of the {len(DEVELOPMENT_VOICES)} development
voices ({", ".join(voices)}), decided with the station's constants as it decides now (a
stop either ear hears clearly is acted on; Whisper hears every clip pocketsphinx took for
speech) and as it decided before the rule, in the same run.

| voices | stops said | acted on as a stop | stops acted on that nobody said | wrong actions |
| --- | ---: | ---: | ---: | ---: |
{table}

A wrong stop halts a robot nobody asked to halt (safe, but a task is interrupted). The
second-ear rows of "Push-to-talk: spoken requests understood" decide as the station did
before the rule.
"""
    write_section("wrong_stops", "Push-to-talk: stops either ear hears", body)
    return 0


def _row(name: str, counts: dict[str, int]) -> str:
    return (
        f"| {name} | {counts['stops said']} | {counts['acted on']} | {counts['wrong stops']} "
        f"| {counts['wrong actions']} |"
    )


if __name__ == "__main__":
    raise SystemExit(main())
