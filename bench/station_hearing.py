"""How push-to-talk hears: spoken requests through the station's recognizer, its N best
weighed by the simulator's NLU (`vahr.assistant.nbest`), on sets and voices kept apart.

Tuning: every 12th utterance and out-of-domain sentence of the NLU's tuning set
(`vahr/assistant/data/tuning-en-US.yaml`), spoken in turn by the TUNING voices. On it,
and on it only, the constants of `vahr.assistant.nbest` are chosen:

1. SHARPNESS by temperature scaling: the value of the grid that gives the labelled robot
   and zone the highest likelihood among the readings of the labelled intent;
2. MIN_SLOT_CONFIDENCE, MIN_INTENT_CONFIDENCE and MIN_WORD_POSTERIOR by one rule: the most
   requests right less ten times the wrong actions (out-of-domain sentences acted on count
   as wrong actions), ties to the lowest thresholds.

Development: the NLU's development set (`devset-en-US.yaml`, written blind, never tuned
on) spoken by every DEVELOPMENT voice, none of which is a tuning voice (festival is an
engine never tuned on), measured once with the constants chosen on tuning, per engine.

An outcome is `right` (intent and slots as labelled), `wrong` (another robot command, or
any robot command for an out-of-domain sentence), `asks` (the right intent with a robot
or zone asked about or for) or `no action` (nothing heard, or the fallback).

With the second ear (Whisper, `vahr/speech/whisper_stt.py`): the development clips are
also transcribed by Whisper told the fleet's names (`whisper_prompt`), and scored as the
station decides: a request Whisper and pocketsphinx's best transcript read alike is acted
on (`agreement`), anything else is weighed as above, with a robot or zone the two heard
differently asked about (`disputed`). Nothing of it is tuned.

Bad input (silence, white noise, a synthetic chord as music, a 19 s ramble of
out-of-domain sentences) is heard too: none may move a robot. The time from the end of a
clip to the understanding (recognizer plus weighing) is taken for the clips of 2.5 to 3.5 s.
Clips are cached under ~/.cache/vahr/hearing-clips.
Run: `.venv/bin/python bench/station_hearing.py`.
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
import time
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vahr.assistant.evaluation import (  # noqa: E402
    DEVELOPMENT_SET,
    LabelledSet,
    LabelledUtterance,
    outcome,
)
from vahr.assistant.nbest import (  # noqa: E402
    MOVING_TYPES,
    Weighing,
    agreement,
    disputed,
    posteriors,
    weigh,
)
from vahr.assistant.nlu import InteractionModel, Understanding  # noqa: E402
from vahr.assistant.simulator import strip_invocation  # noqa: E402
from vahr.domain.fleet import load_fleet  # noqa: E402
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.speech.audio import Audio, concatenate  # noqa: E402
from vahr.speech.stt import Hypothesis, Recognition  # noqa: E402
from vahr.speech.tts import engine_of, make_synthesizer  # noqa: E402
from vahr.speech.whisper_stt import DECODING, WhisperTranscriber  # noqa: E402
from vahr.station.vocabulary import command_recognizer, whisper_prompt  # noqa: E402

TUNING_SET = DEVELOPMENT_SET.with_name("tuning-en-US.yaml")
TUNING_EVERY = 12
# Two of flite's voices (built from recordings of people, as the station's users are
# people) and one espeak-ng voice; the development voices are none of these.
TUNING_VOICES = ("flite:kal", "flite:awb", "espeak-ng:en-us+m3")
DEVELOPMENT_VOICES = (
    "flite:slt",
    "flite:rms",
    "festival:cmu_us_slt_arctic_hts",
    "espeak-ng:en-us+f2",
)
SHARPNESS_GRID = (1 / 25, 1 / 50, 1 / 100, 1 / 200, 1 / 400, 1 / 800, 1 / 1600)
SLOT_GRID = (0.5, 0.6, 0.7, 0.8, 0.9, 0.95)
INTENT_GRID = (0.5, 0.6, 0.7, 0.8, 0.9)
WORD_GRID = (0.0, 0.05, 0.1, 0.15, 0.2, 0.3)
WRONG_COST = 10
CACHE = Path.home() / ".cache" / "vahr" / "hearing-clips"


@dataclass(frozen=True)
class Clip:
    item: LabelledUtterance
    voice: str
    recognition: Recognition
    seconds: float
    recognizer_s: float


def spoken(voice: str, text: str) -> Audio:
    """`text` in `voice` with 0.3 s of silence either side, as a press of the button has."""
    key = hashlib.sha256(f"{voice}\n{text}".encode()).hexdigest()[:24]
    file = CACHE / f"{key}.wav"
    if file.is_file():
        return Audio.from_wav(file.read_bytes())
    audio = concatenate(
        Audio.silence(0.3), make_synthesizer(voice).synthesize(text), Audio.silence(0.3)
    )
    CACHE.mkdir(parents=True, exist_ok=True)
    file.write_bytes(audio.to_wav())
    return audio


def hear(recognizer: object, items: list[tuple[LabelledUtterance, str]]) -> list[Clip]:
    """Each item spoken and recognized; a recognition is kept beside its clip (keyed by the
    recognizer's sentences too), so a second run of the same sets only re-weighs."""
    vocabulary = "\n".join(recognizer.sentences)  # type: ignore[attr-defined]
    model_key = hashlib.sha256(vocabulary.encode()).hexdigest()[:12]
    clips = []
    for item, voice in items:
        audio = spoken(voice, item.text)
        key = hashlib.sha256(f"{voice}\n{item.text}".encode()).hexdigest()[:24]
        kept = CACHE / f"{key}.{model_key}.json"
        if kept.is_file():
            saved = json.loads(kept.read_text())
            recognition = Recognition(
                saved["text"],
                saved["confidence"],
                saved["accepted"],
                hypotheses=tuple(Hypothesis(t, s) for t, s in saved["hypotheses"]),
            )
            seconds = saved["recognizer_s"]
        else:
            started = time.perf_counter()
            recognition = recognizer.recognize(audio)  # type: ignore[attr-defined]
            seconds = time.perf_counter() - started
            kept.write_text(
                json.dumps(
                    {
                        "text": recognition.text,
                        "confidence": recognition.confidence,
                        "accepted": recognition.accepted,
                        "hypotheses": [(h.text, h.score) for h in recognition.hypotheses],
                        "recognizer_s": seconds,
                    }
                )
            )
        clips.append(Clip(item, voice, recognition, audio.seconds, seconds))
    return clips


def hear_again(whisper: WhisperTranscriber, clips: list[Clip]) -> dict[int, tuple[str, float]]:
    """Whisper's transcript and seconds for each clip (by its index), kept beside the clip
    (keyed by the prompt, the weights and how it decodes too), so a second run only re-reads."""
    heard_by = f"{whisper.weights_sha256}\n{whisper.prompt}\n{DECODING}"
    prompt_key = hashlib.sha256(heard_by.encode()).hexdigest()[:12]
    found = {}
    for n, clip in enumerate(clips):
        key = hashlib.sha256(f"{clip.voice}\n{clip.item.text}".encode()).hexdigest()[:24]
        kept = CACHE / f"{key}.whisper-{prompt_key}.json"
        if kept.is_file():
            saved = json.loads(kept.read_text())
        else:
            started = time.perf_counter()
            text = whisper.transcribe(spoken(clip.voice, clip.item.text))
            saved = {"text": text, "seconds": time.perf_counter() - started}
            kept.write_text(json.dumps(saved))
        found[n] = (saved["text"], saved["seconds"])
    return found


def decide_with_second_ear(
    clip: Clip, second: str, read: Reader, weighing: Weighing
) -> Understanding:
    """What the station acts on with its second ear: the agreement, else the weighing with
    the values the two heard differently asked about. The station asks the second ear only
    when the best transcript reads as a request (`PushToTalk._listen_twice`)."""
    best = clip.recognition.text if clip.recognition.accepted else ""
    if not second or not best or read(best).intent == FALLBACK_INTENT:
        return decide(clip, read, weighing)
    both = agreement(read.model, second, best, read)
    if both is not None:
        return both.understanding
    return disputed(read.model, decide(clip, read, weighing), read(second))


class Reader:
    """The NLU's reading of each transcript, each read once."""

    def __init__(self, model: InteractionModel) -> None:
        self.model = model
        self._read: dict[str, Understanding] = {}

    def __call__(self, text: str) -> Understanding:
        if text not in self._read:
            self._read[text] = self.model.understand(
                strip_invocation(self.model.invocation_name, text)
            )
        return self._read[text]


def decide(clip: Clip, read: Reader, weighing: Weighing) -> Understanding:
    """What the station acts on (as `weigh_recognition`, with each reading read once)."""
    recognition = clip.recognition
    if not recognition.accepted or recognition.confidence < weighing.min_word_posterior:
        return Understanding(FALLBACK_INTENT, confidence=1.0)
    hypotheses = recognition.hypotheses or (Hypothesis(recognition.text, 0.0),)
    return weigh(hypotheses, read, weighing).understanding


def tally(
    clips: list[Clip],
    read: Reader,
    weighing: Weighing,
    seconds: dict[int, str] | None = None,
) -> dict[str, int]:
    """Outcomes of `clips`; with `seconds` (the second ear's transcript of each clip, by
    index), as the station decides with it."""
    counts = {"right": 0, "wrong": 0, "asks": 0, "no action": 0, "ood": 0, "ood acted": 0}
    for n, clip in enumerate(clips):
        if seconds is None:
            got = decide(clip, read, weighing)
        else:
            got = decide_with_second_ear(clip, seconds[n], read, weighing)
        result = outcome(read.model, clip.item, got)
        if clip.item.intent == FALLBACK_INTENT:
            counts["ood"] += 1
            counts["ood acted"] += result == "wrong"
            continue
        counts["no action" if result == "fallback" else result] += 1
    return counts


def log_loss(clips: list[Clip], read: Reader, sharpness: float) -> float:
    """Mean negative log-likelihood of the labelled robot and zone among the readings of
    the labelled intent, the readings weighed with `sharpness`."""
    losses = []
    for clip in clips:
        hypotheses = clip.recognition.hypotheses
        if clip.item.intent == FALLBACK_INTENT or not hypotheses:
            continue
        weights = posteriors(hypotheses, sharpness)
        readings = [read(h.text) for h in hypotheses]
        types = read.model.intent_slots.get(clip.item.intent, {})
        for name, expected in clip.item.slots.items():
            if types.get(name) not in MOVING_TYPES:
                continue
            total = right = 0.0
            for weight, reading in zip(weights, readings, strict=True):
                if reading.intent != clip.item.intent:
                    continue
                total += weight
                value = reading.slots.get(name)
                right += weight * (value is not None and value.id == expected)
            if total > 0:
                losses.append(-math.log(max(right / total, 1e-3)))
    return sum(losses) / len(losses) if losses else float("inf")


def row(name: str, counts: dict[str, int]) -> str:
    requests = counts["right"] + counts["wrong"] + counts["asks"] + counts["no action"]
    rate = lambda key: f"{counts[key] / requests:.1%}" if requests else "-"  # noqa: E731
    ood = f"{counts['ood acted']}/{counts['ood']}"
    return (
        f"| {name} | {counts['right']}/{requests} ({rate('right')}) | {counts['wrong']} "
        f"({rate('wrong')}) | {counts['asks']} | {counts['no action']} | {ood} |"
    )


def bad_input(recognizer: object, read: Reader, weighing: Weighing) -> list[tuple[str, str]]:
    rng = np.random.default_rng(31)
    seconds = np.arange(int(3 * 16_000)) / 16_000
    chord = sum(np.sin(2 * np.pi * f * seconds) for f in (261.6, 329.6, 392.0, 523.3))
    beat = (np.sin(2 * np.pi * 2 * seconds) > 0).astype(float) * 0.5 + 0.5
    ood = LabelledSet.load(DEVELOPMENT_SET).out_of_domain
    ramble = Audio(b"")
    for sentence in ood:
        if ramble.seconds > 17.0:
            break
        ramble = concatenate(ramble, spoken("flite:slt", sentence))
    clips = {
        "silence, 3 s": Audio.silence(3.0),
        "white noise, 3 s": Audio.from_samples(rng.normal(0, 3000, len(seconds))),
        "music (a chord on a beat), 3 s": Audio.from_samples(chord * beat * 4000),
        f"a ramble of out-of-domain sentences, {ramble.seconds:.0f} s": ramble,
    }
    found = []
    for name, audio in clips.items():
        recognition = recognizer.recognize(audio)  # type: ignore[attr-defined]
        got = decide(
            Clip(LabelledUtterance("", FALLBACK_INTENT), "", recognition, 0, 0), read, weighing
        )
        moved = got.intent not in (FALLBACK_INTENT,) and not got.intent.startswith("AMAZON.")
        found.append((name, f"heard {recognition.text!r}: {'MOVES' if moved else 'nothing moves'}"))
    return found


def main() -> int:
    model = InteractionModel.load()
    read = Reader(model)
    recognizer = command_recognizer()
    tuning_set = LabelledSet.load(TUNING_SET)
    tuning_items = [
        *tuning_set.utterances[::TUNING_EVERY],
        *(LabelledUtterance(t, FALLBACK_INTENT) for t in tuning_set.out_of_domain[::TUNING_EVERY]),
    ]
    tuning = hear(
        recognizer,
        [(item, TUNING_VOICES[n % len(TUNING_VOICES)]) for n, item in enumerate(tuning_items)],
    )
    losses = {s: log_loss(tuning, read, s) for s in SHARPNESS_GRID}
    sharpness = min(losses, key=lambda s: losses[s])
    grid = {
        (slot, intent, word): tally(tuning, read, Weighing(sharpness, slot, intent, word))
        for slot in SLOT_GRID
        for intent in INTENT_GRID
        for word in WORD_GRID
    }

    def gain(key: tuple[float, float, float]) -> float:
        counts = grid[key]
        return counts["right"] - WRONG_COST * (counts["wrong"] + counts["ood acted"])

    # Ties go to the lowest thresholds (the fewest questions).
    chosen = max(grid, key=lambda key: (gain(key), -key[0], -key[1], -key[2]))
    # The development set is measured with what the tuning chose (the station's constants
    # are set to it; the text below says whether they agree).
    used = Weighing(sharpness, *chosen)
    station = Weighing()
    development_set = LabelledSet.load(DEVELOPMENT_SET)
    development = {
        voice: hear(recognizer, [(item, voice) for item in development_set.items()])
        for voice in DEVELOPMENT_VOICES
    }
    per_engine: dict[str, list[Clip]] = defaultdict(list)
    for voice, clips in development.items():
        per_engine[engine_of(voice)].extend(clips)
    human_like = [c for v, cs in development.items() if engine_of(v) != "espeak-ng" for c in cs]
    header = (
        "| | requests right | wrong actions | asks | no action | out of domain acted on |\n"
        "| --- | --- | --- | --- | --- | --- |"
    )
    loss_row = " | ".join(f"1/{round(1 / s)}: {loss:.3f}" for s, loss in losses.items())
    tuning_rows = "\n".join(
        row(f"slot {slot:g}, intent {intent:g}, word {word:g}", grid[(slot, intent, word)])
        for slot, intent, word in grid
        if sum(a == b for a, b in zip((slot, intent, word), chosen, strict=True)) >= 2
    )
    single = Weighing(used.sharpness, 0.0, 0.0, 0.0)
    dev_rows = "\n".join(row(v, tally(c, read, used)) for v, c in development.items())
    engine_rows = "\n".join(row(e, tally(c, read, used)) for e, c in per_engine.items())
    best_only = row(
        "human-like voices, acting on every reading (thresholds 0)", tally(human_like, read, single)
    )
    whisper = WhisperTranscriber(whisper_prompt(load_fleet()))
    second_ear = {voice: hear_again(whisper, clips) for voice, clips in development.items()}
    second_rows = "\n".join(
        row(v, tally(c, read, used, {n: t for n, (t, _) in second_ear[v].items()}))
        for v, c in development.items()
    )
    human_second: dict[int, str] = {}
    for voice in development:
        if engine_of(voice) != "espeak-ng":
            offset = len(human_second)
            human_second.update({offset + n: t for n, (t, _) in second_ear[voice].items()})
    second_human = row("human-like voices together", tally(human_like, read, used, human_second))
    station_human = row("human-like voices together", tally(human_like, read, used))
    whisper_3s = [
        second_ear[v][n][1]
        for v, clips in development.items()
        for n, c in enumerate(clips)
        if 2.5 <= c.seconds <= 3.5
    ]
    near_3s = [
        c.recognizer_s for cs in (tuning, *development.values()) for c in cs
        if 2.5 <= c.seconds <= 3.5
    ]  # fmt: skip
    weigh_s = []
    for clip in development["flite:slt"][:60]:
        started = time.perf_counter()
        decide(clip, Reader(model), used)
        weigh_s.append(time.perf_counter() - started)
    load = Path("/proc/loadavg").read_text().split()[:3]
    bad = "\n".join(f"- {name}: {verdict}" for name, verdict in bad_input(recognizer, read, used))
    body = f"""
Spoken requests heard by the station's recognizer; its N best transcripts (at most 10)
understood by the simulator's NLU and weighed into one understanding
(`vahr/assistant/nbest.py`). Load average {" ".join(load)} (the machine is shared).

**Tuning** ({len(tuning)} clips: every {TUNING_EVERY}th sentence of {TUNING_SET.name},
spoken in turn by {", ".join(TUNING_VOICES)}). Mean negative log-likelihood of the labelled
robot and zone by sharpness (decoder log units per factor e): {loss_row}; the lowest is
1/{round(1 / sharpness)}. With it, the thresholds (rows: those differing from the chosen
ones in at most one of the three):

{header}
{tuning_rows}

The rule (most right less {WRONG_COST} x wrong actions) picks slot {chosen[0]:g}, intent
{chosen[1]:g}, word posterior {chosen[2]:g}; the station uses sharpness
1/{round(1 / station.sharpness)}, slot {station.min_slot_confidence:g}, intent
{station.min_intent_confidence:g}, word posterior {station.min_word_posterior:g}.

**Development** ({DEVELOPMENT_SET.name}: {len(development_set.utterances)} requests and
{len(development_set.out_of_domain)} out-of-domain sentences, written blind; spoken by
voices never tuned on; measured once with the constants chosen above). Per voice:

{header}
{dev_rows}

Per engine (festival was never tuned on; flite's slt and rms, and espeak-ng's en-us+f2,
were not among the tuning voices):

{header}
{engine_rows}
{best_only}

**With the second ear** (Whisper tiny.en told "{whisper.prompt}", decoded with {DECODING};
a request it and
pocketsphinx's best transcript read alike is acted on, anything else weighed as above with
a robot or zone the two heard differently asked about; the same development clips, nothing
tuned):

{header}
{second_rows}
{second_human}

and, for comparison, the N best alone over the same human-like clips:

{header}
{station_human}

Whisper takes median {median(whisper_3s) * 1000:.0f} ms, p95
{percentile(whisper_3s, 95) * 1000:.0f} ms for the clips of 2.5 to 3.5 s, beside pocketsphinx
(both at once on the station).

Bad input, none of which may move a robot:

{bad}

Time from the end of a clip to the understanding, for the {len(near_3s)} clips of 2.5 to
3.5 s: recognizer median {median(near_3s) * 1000:.0f} ms, p95
{percentile(near_3s, 95) * 1000:.0f} ms; weighing the N best (each reading understood
afresh) median {median(weigh_s) * 1000:.0f} ms, p95 {percentile(weigh_s, 95) * 1000:.0f} ms.
"""
    write_section("station_hearing", "Push-to-talk: spoken requests understood", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
