"""The robot's hearing on the spoken evaluation set: accuracy per condition and intent, and
time per clip (the whole hearing beside the recognizer alone).

Renders `robot_agent/voice/data/hearing-eval.yaml` (three espeak-ng voices, clean, 20 dB
and 10 dB SNR, answers and unrelated speech) into a temporary directory, hears every clip
as `robot-agent hear --eval` does, and times the recognizer alone on the same clips. Also
the start-up: building the recognizer (its language model, vocabulary and adapted model),
and the sense check trained (a cold cache, scikit-learn imported) or loaded from the cache.
With `--voices ENGINE:VOICE,...` it renders the same set clean in those voices instead (by
default flite's slt, rms, awb and kal and festival's HTS voice: voices built from people's
recordings, none of which the hearing was tuned on) and writes the figures per engine and
voice in a section of their own.
Run: `.venv/bin/python bench/hearing.py [--phrasings FILE] [--voices [LIST]]`.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import msgspec
from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from robot_agent.voice.answers import WeatherAnswers  # noqa: E402
from robot_agent.voice.evaluation import (  # noqa: E402
    EVALUATION_SET,
    Phrasings,
    load_manifest,
    render,
    score,
    synthesizer_for_voice,
)
from robot_agent.voice.hearing import Hearing, weather_recognizer  # noqa: E402
from robot_agent.voice.interpreter import LocalInterpreter  # noqa: E402
from robot_agent.voice.sense import SenseCheck  # noqa: E402
from vahr.speech.audio import Audio  # noqa: E402
from vahr.speech.tts import engine_of, voice_names  # noqa: E402

HUMAN_LIKE = (*voice_names()["flite"], *voice_names()["festival"])


def ms(values: list[float]) -> str:
    return f"{median(values) * 1000:.0f} ms | {percentile(values, 99) * 1000:.0f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--phrasings", type=Path, default=EVALUATION_SET)
    parser.add_argument("--voices", nargs="?", const=",".join(HUMAN_LIKE), default=None)
    args = parser.parse_args()
    phrasings = Phrasings.load(args.phrasings)
    if args.voices:
        many_voices(phrasings, args.voices.split(","), args.phrasings.name)
        return
    with tempfile.TemporaryDirectory() as cache:
        # Built as on a robot's first start: its model cache empty.
        started = time.perf_counter()
        answers = WeatherAnswers.load()
        recognizer = weather_recognizer(answers, cache_dir=Path(cache))
        build_s = time.perf_counter() - started
    with tempfile.TemporaryDirectory() as cache:
        begun = time.perf_counter()
        SenseCheck.train(answers, cache_dir=Path(cache))
        sense_cold_s = time.perf_counter() - begun
        begun = time.perf_counter()
        sense = SenseCheck.train(answers, cache_dir=Path(cache))
        sense_warm_s = time.perf_counter() - begun
    hearing = Hearing(recognizer, LocalInterpreter(answers), sense=sense)
    with tempfile.TemporaryDirectory() as folder:
        directory = Path(folder)
        manifest = render(phrasings, directory, synthesizer_for_voice, source=args.phrasings.name)
        report = score(directory, hearing.hear, time.perf_counter)
        alone: list[float] = []
        for clip in load_manifest(directory).clips:
            audio = Audio.from_wav((directory / clip.file).read_bytes())
            begun = time.perf_counter()
            recognizer.recognize(audio)
            alone.append(time.perf_counter() - begun)
    accepted = report.unrelated()
    body = f"""Set: `{args.phrasings.name}`, {len(manifest.clips)} clips (voices
{", ".join(phrasings.voices)}; clean, {" and ".join(f"{s:g} dB" for s in phrasings.snr_db)} SNR),
audio sha256 `{manifest.digest()[:16]}`.

| condition | expected | clips | right | wrong intent | fallback (unknown) |
| --- | --- | --- | --- | --- | --- |
{report.table().split(chr(10), 2)[2]}

Unrelated speech accepted as an answer: {accepted.counts["wrong"]} of {accepted.total}
({accepted.rate("wrong"):.1%}).

| per clip | p50 | p99 |
| --- | --- | --- |
| hearing (recognize, interpret, sense check) | {ms(report.seconds)} |
| recognizer alone | {ms(alone)} |

Building the recognizer at start-up (language model, vocabulary, adapted model):
{build_s * 1000:.0f} ms. The sense check: {sense_cold_s * 1000:.0f} ms trained (cold cache, with
scikit-learn's import), {sense_warm_s * 1000:.0f} ms from the cache."""
    write_section("hearing", "The robot's hearing (spoken evaluation set)", body)


def many_voices(phrasings: Phrasings, voices: list[str], source: str) -> None:
    """The set spoken clean in each of `voices`, heard as `robot-agent hear --eval` does."""
    answers = WeatherAnswers.load()
    hearing = Hearing(
        weather_recognizer(answers), LocalInterpreter(answers), sense=SenseCheck.train(answers)
    )
    rows = []
    totals: dict[str, list[int]] = {}
    for voice in voices:
        spoken = msgspec.structs.replace(phrasings, voices=[voice], snr_db=[])
        with tempfile.TemporaryDirectory() as folder:
            render(spoken, Path(folder), synthesizer_for_voice, source=source)
            report = score(Path(folder), hearing.hear, time.perf_counter)
        said, unrelated = report.answers("clean"), report.unrelated()
        counts = [said.counts["right"], said.counts["wrong"], said.total]
        counts += [unrelated.counts["wrong"], unrelated.total]
        total = totals.setdefault(engine_of(voice), [0, 0, 0, 0, 0])
        totals[engine_of(voice)] = [a + b for a, b in zip(total, counts, strict=True)]
        rows.append(row(voice, counts))
    rows += [row(f"**{engine}**", counts) for engine, counts in totals.items()]
    load = " ".join(Path("/proc/loadavg").read_text().split()[:3])
    body = f"""Set: `{source}`, clean, each voice in turn (load average {load}). The hearing was
tuned on espeak-ng voices only (hearing-tuning.yaml); none of these voices was tuned on.

| voice | answers right | wrong weather | unrelated accepted as an answer |
| --- | --- | --- | --- |
{chr(10).join(rows)}"""
    write_section("hearing_voices", "The robot's hearing in voices built from people", body)


def row(name: str, counts: list[int]) -> str:
    right, wrong, total, accepted, unrelated = counts
    return (
        f"| {name} | {right}/{total} ({right / max(total, 1):.1%}) | {wrong} | "
        f"{accepted}/{unrelated} ({accepted / max(unrelated, 1):.1%}) |"
    )


if __name__ == "__main__":
    main()
