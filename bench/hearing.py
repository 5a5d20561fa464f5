"""The robot's hearing on the spoken evaluation set: accuracy per condition and intent, and
time per clip (the whole hearing beside the recognizer alone).

Renders `robot_agent/voice/data/hearing-eval.yaml` (three espeak-ng voices, clean, 20 dB
and 10 dB SNR, answers and unrelated speech) into a temporary directory, hears every clip
as `robot-agent hear --eval` does, and times the recognizer alone on the same clips. Also
the start-up: building the recognizer (its language model, vocabulary and adapted model),
and the sense check trained (a cold cache, scikit-learn imported) or loaded from the cache.
Run: `.venv/bin/python bench/hearing.py [--phrasings FILE]`.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from robot_agent.voice.answers import WeatherAnswers  # noqa: E402
from robot_agent.voice.evaluation import (  # noqa: E402
    EVALUATION_SET,
    Phrasings,
    load_manifest,
    render,
    score,
)
from robot_agent.voice.hearing import Hearing, weather_recognizer  # noqa: E402
from robot_agent.voice.interpreter import LocalInterpreter  # noqa: E402
from robot_agent.voice.sense import SenseCheck  # noqa: E402
from vahr.speech.audio import Audio  # noqa: E402
from vahr.speech.tts import EspeakSynthesizer  # noqa: E402


def ms(values: list[float]) -> str:
    return f"{median(values) * 1000:.0f} ms | {percentile(values, 99) * 1000:.0f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--phrasings", type=Path, default=EVALUATION_SET)
    args = parser.parse_args()
    phrasings = Phrasings.load(args.phrasings)
    started = time.perf_counter()
    answers = WeatherAnswers.load()
    recognizer = weather_recognizer(answers)
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
        manifest = render(phrasings, directory, EspeakSynthesizer, source=args.phrasings.name)
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


if __name__ == "__main__":
    main()
