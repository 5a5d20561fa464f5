"""The spoken evaluation of the robot's hearing: render a set of answers, score a hearing.

A phrasings file (`data/hearing-eval.yaml`, `data/hearing-tuning.yaml`) names voices
(`ENGINE:VOICE` as `vahr.speech.tts.make_synthesizer` reads them, `flite:slt`,
`festival:cmu_us_slt_arctic_hts`; a bare name is an espeak-ng voice), noise levels, a seed,
the answers per intent and unrelated sentences. `render`
speaks every sentence in every voice, clean and with white noise at each SNR, into a
directory with a `manifest.json`; the same file gives byte-identical audio on every run
(the synthesizers are deterministic, and each clip's noise comes from a generator seeded by the
set's seed and the clip's name, not by the order of rendering). `score` hears every clip
of such a directory and counts, per condition and expected intent, what came back:

- right: the expected intent (for an unrelated sentence, `unknown`);
- wrong: the other weather (for an unrelated sentence, any weather: accepted as an answer);
- fallback: `unknown` for an answer (the executor asks again).
"""

from __future__ import annotations

import hashlib
import json
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import numpy as np

from vahr.domain.text import normalize
from vahr.errors import VahrError
from vahr.speech.audio import Audio, add_white_noise
from vahr.speech.scoring import OutcomeTally, read_labelled_set

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.voice.port import Heard

DATA = Path(__file__).resolve().parent / "data"
EVALUATION_SET = DATA / "hearing-eval.yaml"
TUNING_SET = DATA / "hearing-tuning.yaml"
MANIFEST = "manifest.json"
UNRELATED = "unrelated"
OUTCOMES = ("right", "wrong", "fallback")


class Phrasings(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """What to render: voices, noise levels (dB SNR), seed, answers and unrelated speech."""

    voices: list[str]
    snr_db: list[float]
    seed: int
    answers: dict[str, list[str]]
    unrelated: list[str]

    @classmethod
    def load(cls, path: Path) -> Phrasings:
        return read_labelled_set(path, cls)

    def sentences(self) -> list[tuple[str, str, str]]:
        """(name, expected intent, text) for every sentence, answers first."""
        found = [
            (f"{intent}-{n:03d}", intent, text)
            for intent, texts in self.answers.items()
            for n, text in enumerate(texts, 1)
        ]
        found += [(f"{UNRELATED}-{n:03d}", "unknown", t) for n, t in enumerate(self.unrelated, 1)]
        return found

    def normalized(self) -> set[str]:
        return {normalize(text) for _, _, text in self.sentences()}


class Clip(msgspec.Struct, frozen=True):
    file: str
    text: str
    expected: str
    voice: str
    condition: str
    sha256: str


class Manifest(msgspec.Struct, frozen=True):
    source: str
    clips: list[Clip]

    def digest(self) -> str:
        """One fingerprint of all the audio: equal digests mean identical sets."""
        joined = "".join(f"{clip.file}:{clip.sha256}\n" for clip in self.clips)
        return hashlib.sha256(joined.encode()).hexdigest()


def synthesizer_for_voice(voice: str) -> Any:
    """The synthesizer of a phrasings file's voice: `ENGINE:VOICE`, or a bare espeak-ng
    voice name (`en-us+f4`) as the older sets list them."""
    from vahr.speech.tts import make_synthesizer

    return make_synthesizer(voice if ":" in voice else f"espeak-ng:{voice}")


def condition_name(snr_db: float | None) -> str:
    return "clean" if snr_db is None else f"snr{snr_db:g}"


def render(
    phrasings: Phrasings,
    directory: Path,
    synthesizer_for: Callable[[str], Any],
    *,
    source: str = "",
    voices_in_turn: bool = False,
) -> Manifest:
    """Speak every sentence in every voice, clean and at each SNR, into `directory`; with
    `voices_in_turn`, each sentence in one voice only, the voices taken in turn (a third of
    the clips for three voices, every sentence, voice and condition among them)."""
    clips: list[Clip] = []
    conditions: list[float | None] = [None, *phrasings.snr_db]
    every = phrasings.sentences()
    for turn, voice in enumerate(phrasings.voices):
        tts = synthesizer_for(voice)
        sentences = every[turn :: len(phrasings.voices)] if voices_in_turn else every
        for name, expected, text in sentences:
            clean: Audio = tts.synthesize(text)
            for snr in conditions:
                condition = condition_name(snr)
                audio = clean
                if snr is not None:
                    audio = add_white_noise(clean, snr, _noise(phrasings, voice, name, condition))
                relative = f"{condition}/{voice}/{name}.wav"
                path = directory / relative
                path.parent.mkdir(parents=True, exist_ok=True)
                wav = audio.to_wav()
                path.write_bytes(wav)
                digest = hashlib.sha256(wav).hexdigest()
                clips.append(Clip(relative, text, expected, voice, condition, digest))
    manifest = Manifest(source, clips)
    (directory / MANIFEST).write_bytes(msgspec.json.format(msgspec.json.encode(manifest)))
    return manifest


def _noise(phrasings: Phrasings, voice: str, name: str, condition: str) -> np.random.Generator:
    # Seeded by the clip, not by rendering order: any subset renders the same noise.
    clip = zlib.crc32(f"{voice}/{name}/{condition}".encode())
    return np.random.default_rng([phrasings.seed, clip])


def held_out_sentences() -> set[str]:
    """Every sentence of the evaluation and tuning sets, normalized: what nothing the hearing
    is built from may hold."""
    return Phrasings.load(EVALUATION_SET).normalized() | Phrasings.load(TUNING_SET).normalized()


def load_manifest(directory: Path) -> Manifest:
    path = directory / MANIFEST
    try:
        return msgspec.json.decode(path.read_bytes(), type=Manifest)
    except OSError as err:
        raise VahrError(
            f"{path}: {err.strerror} (make the set with `robot-agent hear --make-eval-set DIR`)"
        ) from err
    except msgspec.DecodeError as err:
        raise VahrError(f"{path}: not a manifest of spoken clips: {err}") from err


@dataclass
class Report:
    """Tallies per condition and expected intent, plus every clip that went wrong."""

    tallies: dict[str, dict[str, OutcomeTally]] = field(default_factory=dict)
    misses: list[dict[str, Any]] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)

    def add(self, clip: Clip, heard: Heard, seconds: float) -> None:
        outcome = outcome_of(clip.expected, heard.intent)
        group = clip.expected if clip.expected != "unknown" else UNRELATED
        by_intent = self.tallies.setdefault(clip.condition, {})
        by_intent.setdefault(group, OutcomeTally(OUTCOMES)).counts[outcome] += 1
        self.seconds.append(seconds)
        if outcome != "right":
            self.misses.append(
                {"file": clip.file, "said": clip.text, "expected": clip.expected,
                 "intent": heard.intent, "heard": heard.text, "reason": heard.reason}
            )  # fmt: skip

    def tally(self, condition: str, group: str) -> OutcomeTally:
        return self.tallies.get(condition, {}).get(group, OutcomeTally(OUTCOMES))

    def answers(self, condition: str) -> OutcomeTally:
        """Sunny and rainy together, for one condition."""
        joined = OutcomeTally(OUTCOMES)
        for group, tally in self.tallies.get(condition, {}).items():
            if group != UNRELATED:
                joined.add(tally)
        return joined

    def unrelated(self) -> OutcomeTally:
        joined = OutcomeTally(OUTCOMES)
        for by_intent in self.tallies.values():
            if UNRELATED in by_intent:
                joined.add(by_intent[UNRELATED])
        return joined

    def to_json(self) -> dict[str, Any]:
        return {
            "conditions": {
                condition: {
                    **{group: tally.to_json() for group, tally in sorted(by_intent.items())},
                    "answers": self.answers(condition).to_json(),
                }
                for condition, by_intent in self.tallies.items()
            },
            "unrelated_accepted_rate": round(self.unrelated().rate("wrong"), 4),
            "clips": len(self.seconds),
            "misses": self.misses,
        }

    def table(self) -> str:
        """The per-condition, per-intent table as Markdown."""
        rows = [
            "| condition | expected | clips | right | wrong intent | fallback (unknown) |",
            "| --- | --- | --- | --- | --- | --- |",
        ]
        for condition, by_intent in self.tallies.items():
            groups = [*sorted(g for g in by_intent if g != UNRELATED), UNRELATED]
            for group in groups:
                tally = by_intent.get(group)
                if tally is None:
                    continue
                wrong = "accepted as an answer" if group == UNRELATED else "wrong intent"
                rows.append(
                    f"| {condition} | {group} | {tally.total} | {tally.rate('right'):.1%} | "
                    f"{tally.rate('wrong'):.1%}{' (' + wrong + ')' if group == UNRELATED else ''} "
                    f"| {tally.rate('fallback'):.1%} |"
                )
        return "\n".join(rows)


def outcome_of(expected: str, intent: str) -> str:
    if intent == expected:
        return "right"
    return "fallback" if intent == "unknown" else "wrong"


def score(directory: Path, hear: Callable[[Audio], Heard], clock: Callable[[], float]) -> Report:
    """Hear every clip of a rendered set and tally the outcomes."""
    manifest = load_manifest(directory)
    report = Report()
    for clip in manifest.clips:
        path = directory / clip.file
        try:
            audio = Audio.from_wav(path.read_bytes())
        except OSError as err:
            raise VahrError(f"{path}: {err.strerror}") from err
        started = clock()
        heard = hear(audio)
        report.add(clip, heard, clock() - started)
    return report


def manifest_json(manifest: Manifest, directory: Path) -> str:
    return json.dumps(
        {"directory": str(directory), "clips": len(manifest.clips), "sha256": manifest.digest()}
    )
