"""How push-to-talk hears: spoken requests through the station's recognizer and the
simulator's understanding, on labelled sets kept apart.

Each utterance of the NLU's labelled sets (`vahr/local/alexa/data/`: the tuning set, then
the development set, which nothing here was tuned on) is spoken by espeak-ng (two voices in
turn, every third one with white noise at 20 dB SNR, seeded), recognized by the station's
recognizer (a language model of the interaction model's sentences), and the transcript is
understood by the simulator's NLU. An outcome is `right` (intent and slots as labelled),
`wrong` (another action, or any action for an out-of-domain sentence), `asks` (right intent,
a slot left to ask for) or `no action` (nothing heard with enough confidence, or the
fallback intent: the station says "Sorry, I didn't catch that").

The recognizer's threshold (`vahr.station.voice.MIN_CONFIDENCE`) is chosen on the
tuning set by one rule: the most requests right among the thresholds that let at most 10%
of out-of-domain sentences be acted on. The development set is only measured.
Run: `.venv/bin/python bench/station_hearing.py`.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from _results import median, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vahr.local.alexa.evaluation import DEVELOPMENT_SET, LabelledSet, outcome  # noqa: E402
from vahr.local.alexa.nlu import FALLBACK, InteractionModel  # noqa: E402
from vahr.local.alexa.simulator import strip_invocation  # noqa: E402
from vahr.speech.audio import Audio, add_white_noise  # noqa: E402
from vahr.speech.tts import EspeakSynthesizer  # noqa: E402
from vahr.station.vocabulary import command_recognizer  # noqa: E402
from vahr.station.voice import MIN_CONFIDENCE  # noqa: E402

TUNING_SET = DEVELOPMENT_SET.with_name("tuning-en-US.yaml")
VOICES = ("en-us+f2", "en-us+m3")
THRESHOLDS = (0.0, 0.05, 0.1, 0.15, 0.2, 0.3)
MAX_OUT_OF_DOMAIN_ACTED = 0.10

Heard = tuple[str, float, float]  # transcript, confidence, recognizer seconds


def hear(labelled: LabelledSet, recognizer: object) -> list[Heard]:
    voices = [EspeakSynthesizer(voice) for voice in VOICES]
    heard = []
    for index, item in enumerate(labelled.items()):
        spoken = voices[index % len(voices)].synthesize(item.text)
        audio = Audio(Audio.silence(0.3).pcm + spoken.pcm + Audio.silence(0.3).pcm)
        if index % 3 == 2:
            audio = add_white_noise(audio, 20.0, np.random.default_rng(index))
        started = time.perf_counter()
        recognition = recognizer.recognize(audio)  # type: ignore[attr-defined]
        heard.append((recognition.text, recognition.confidence, time.perf_counter() - started))
    return heard


def tally(
    model: InteractionModel, labelled: LabelledSet, heard: list[Heard], threshold: float
) -> dict[str, int]:
    counts = {"right": 0, "wrong": 0, "asks": 0, "no action": 0, "ood": 0, "ood acted": 0}
    for item, (text, confidence, _) in zip(labelled.items(), heard, strict=True):
        result = "fallback"
        if text and confidence >= threshold:
            result = outcome(
                model, item, model.understand(strip_invocation(model.invocation_name, text))
            )
        if item.intent == FALLBACK:
            counts["ood"] += 1
            counts["ood acted"] += result == "wrong"
            continue
        counts["no action" if result == "fallback" else result] += 1
    return counts


def text_only(model: InteractionModel, labelled: LabelledSet) -> dict[str, int]:
    """The same set understood from its text: what the NLU does without speech."""
    exact = [(item.text, 1.0, 0.0) for item in labelled.items()]
    return tally(model, labelled, exact, 0.0)


def row(name: str, counts: dict[str, int]) -> str:
    requests = counts["right"] + counts["wrong"] + counts["asks"] + counts["no action"]
    return (
        f"| {name} | {counts['right']}/{requests} | {counts['wrong']} | {counts['asks']} | "
        f"{counts['no action']} | {counts['ood acted']}/{counts['ood']} |"
    )


def main() -> int:
    model = InteractionModel.load()
    recognizer = command_recognizer()
    sets = {
        "tuning": LabelledSet.load(TUNING_SET),
        "development": LabelledSet.load(DEVELOPMENT_SET),
    }
    heard = {name: hear(labelled, recognizer) for name, labelled in sets.items()}
    tuning = {t: tally(model, sets["tuning"], heard["tuning"], t) for t in THRESHOLDS}
    allowed = [t for t, c in tuning.items() if c["ood acted"] <= MAX_OUT_OF_DOMAIN_ACTED * c["ood"]]
    chosen = max(allowed, key=lambda t: (tuning[t]["right"], t)) if allowed else None
    header = (
        "| | requests right | wrong action | asks for a slot | no action "
        "| out of domain acted on |\n| --- | --- | --- | --- | --- | --- |"
    )
    tuning_rows = "\n".join(row(f"threshold {t:g}", c) for t, c in tuning.items())
    development = tally(model, sets["development"], heard["development"], MIN_CONFIDENCE)
    seconds = [s for found in heard.values() for _, _, s in found]
    body = f"""
Spoken by espeak-ng ({" and ".join(VOICES)} in turn, every third at 20 dB SNR), heard by the
station's recognizer, understood by the simulator's NLU. The rule picks the threshold with
the most requests right among those acting on at most {MAX_OUT_OF_DOMAIN_ACTED:.0%} of the
out-of-domain sentences.

Tuning set ({TUNING_SET.name}):

{header}
{tuning_rows}

The rule picks {chosen if chosen is not None else "none"}; the station uses
{MIN_CONFIDENCE:g}.

Development set ({DEVELOPMENT_SET.name}), measured only, at {MIN_CONFIDENCE:g}, beside
the same sentences understood from their text:

{header}
{row("spoken, push-to-talk", development)}
{row("text (no speech)", text_only(model, sets["development"]))}

The recognizer's time per utterance: median {median(seconds) * 1000:.0f} ms.
"""
    write_section("station_hearing", "Push-to-talk: spoken requests understood", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
