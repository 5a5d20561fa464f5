"""The sense check's training sentences as the robot hears them.

The sense check reads what the recognizer made of the speech, not what was said: "she has a
sunny personality" may come out "she have a very sunny personality", and noise turns words
into others. Trained on written sentences only, the classifier meets those forms first at
run time. So `make sense-heard` speaks every training sentence of the sense check with
espeak-ng, in voices no hearing set uses (the adaptation's), clean and with white noise at
20 dB and 10 dB SNR, hears each clip with the robot's own recognizer and writes the texts,
still labelled answer or other, to `data/answer-sense-heard.yaml`; `SenseCheck.train` learns
from them beside the written ones. A heard text that is a sentence of the evaluation or
tuning sets is left out, so they stay held out.

Chosen on the tuning set (docs/history/voice-tuning.md, "The ninth round"). About ten
minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import sys
import zlib
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import yaml

from robot_agent.voice.adaptation import VOICES
from robot_agent.voice.answers import WeatherAnswers
from robot_agent.voice.sense import HEARD_FILE, SENSE_FILE, training_sentences
from vahr.domain.text import normalize
from vahr.speech.audio import add_white_noise
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Sequence

    from vahr.speech.audio import Audio

# Each sentence is spoken in one of these voices, in turn: two of the adaptation's, which
# neither the tuning nor the evaluation set uses.
HEARD_VOICES = (VOICES[1], VOICES[5])
CONDITIONS: tuple[float | None, ...] = (None, 20.0, 10.0)
SEED = 2611


def heard_texts(
    sentences: Sequence[str],
    speak: Callable[[str, str], Audio],
    hear: Callable[[Audio], str],
) -> list[str]:
    """What `hear` makes of each sentence spoken by `speak(voice, text)`, clean and in noise;
    empty hearings are dropped, repeats kept once."""
    found: dict[str, None] = {}
    for index, sentence in enumerate(sentences):
        clean = speak(HEARD_VOICES[index % len(HEARD_VOICES)], sentence)
        for snr in CONDITIONS:
            audio = clean
            if snr is not None:
                rng = np.random.default_rng([SEED, zlib.crc32(f"{sentence}/{snr}".encode())])
                audio = add_white_noise(clean, snr, rng)
            text = normalize(hear(audio))
            if text:
                found.setdefault(text, None)
    return list(found)


def write_heard(
    path: Path, answers: Iterable[str], other: Iterable[str], held_out: set[str]
) -> tuple[int, int]:
    """Write the heard texts, leaving out held-out sentences; the counts written."""
    kept = {
        "answers": [t for t in answers if t not in held_out],
        "other": [t for t in other if t not in held_out],
    }
    header = (
        "# The sense check's training sentences as the robot hears them: written by\n"
        "# `make sense-heard` (robot_agent/voice/sense_heard.py); do not edit by hand.\n"
    )
    path.write_text(header + yaml.safe_dump(kept, width=100, sort_keys=False))
    return len(kept["answers"]), len(kept["other"])


def main(argv: Sequence[str] | None = None) -> int:
    """Remake data/answer-sense-heard.yaml from the sense check's training sentences."""
    from robot_agent.voice.evaluation import held_out_sentences
    from robot_agent.voice.hearing import weather_recognizer
    from vahr.speech.tts import EspeakSynthesizer

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("--out", type=Path, default=HEARD_FILE, help=f"default: {HEARD_FILE}")
    args = parser.parse_args(argv)
    synthesizers = {voice: EspeakSynthesizer(voice) for voice in HEARD_VOICES}
    try:
        answers = WeatherAnswers.load()
        recognizer = weather_recognizer(answers)
        said, other = training_sentences(answers, SENSE_FILE, heard_file=None)

        def speak(voice: str, text: str) -> Audio:
            return synthesizers[voice].synthesize(text)

        def hear(audio: Audio) -> str:
            return recognizer.recognize(audio).text

        counts = write_heard(
            args.out,
            heard_texts(said, speak, hear),
            heard_texts(other, speak, hear),
            held_out_sentences(),
        )
    except SpeechError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    print(f"{args.out}: {counts[0]} answers and {counts[1]} other sentences as heard")
    return 0


if __name__ == "__main__":
    sys.exit(main())
