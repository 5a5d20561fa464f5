"""Speech recognition: pocketsphinx offline with a grammar of the expected answers.

Free-form recognition of synthetic speech is poor, so the decoder is constrained to a JSGF
grammar of the expected phrases. A grammar always yields an in-grammar guess, so each
result is checked two ways before it is accepted:

- the hypothesis must be a whole phrase (a decoder that ran out of grammar stops early),
  and not a decoy: the grammar also holds phrases that are *not* answers (other weather,
  what robots say in the room, frequent short words), so speech outside the answers has
  somewhere to go other than the nearest answer;
- a likelihood ratio: the grammar path's acoustic score per frame against an
  unconstrained phone loop over the same audio (all senones scored, so both are measured
  against the same per-frame best). In-grammar speech follows the phone loop closely;
  anything else falls far behind it. The ratio is mapped to a 0..1 confidence.

Silence never reaches the decoder: an energy detector finds no speech first. When the
audio holds several sentences (the skill may add one after its answer), the prefixes
ending at each pause are tried as well and the most confident accepted one wins.
pocketsphinx is imported here and in `lm_stt` (the open recognizer), nowhere else.
"""

from __future__ import annotations

import math
import threading
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from vahr.speech.audio import SAMPLE_RATE, SAMPLE_WIDTH, Audio, SpeechDetector
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator

# Logistic mapping of the per-frame log-likelihood ratio (pocketsphinx log units, base
# 1.0001) to a confidence. Measured on espeak-ng speech in two voices, clean and at 20 dB
# SNR: in-grammar answers scored -6 to +40, unrelated sentences -31 to -18. The midpoint
# sits between the two; see docs/voice.md.
RATIO_MIDPOINT = -12.0
RATIO_SCALE = 4.0
DEFAULT_MIN_CONFIDENCE = 0.8
# Competing phrases that are never accepted. Measured (bench/voice_roundtrip.py): without
# them 16 of 60 unrelated utterances were taken for an answer, with them 1 of 60, and every
# answer was still understood.
DEFAULT_DECOYS = (
    "the weather is cloudy", "the weather is windy", "the weather is cold",
    "the weather is hot", "it is cloudy", "it is snowing", "it is windy", "it is cold",
    "it is hot", "it is foggy", "thank you", "okay", "yes", "no", "stop", "hello", "go",
    "i am", "i am going", "please", "one", "two", "zone", "robot", "deliver", "arrived",
    "what", "time", "battery", "there", "right", "so", "and", "the", "to", "a", "is", "in",
    "has",
)  # fmt: skip
MAX_PREFIXES = 3
# Speech runs at about 10-15 phones a second; a short phrase stretched over much longer
# speech ("sunny" for "I am going to zone B") is a forced guess, not an answer.
MIN_PHONES_PER_SECOND = 4.0
# Context kept around a sentence cut at a pause: the decoder expects some silence.
_MARGIN_SAMPLES = SAMPLE_RATE * 150 // 1000


@dataclass(frozen=True)
class HeardWord:
    """One recognized word and the decoder's posterior probability for it (0..1)."""

    text: str
    posterior: float


@dataclass(frozen=True)
class Hypothesis:
    """One of the recognizer's N best transcripts and its path score: the log-likelihood in
    the decoder's log units (base 1.0001), comparable only between hypotheses of one clip."""

    text: str
    score: float


@dataclass(frozen=True)
class Recognition:
    """What was heard: `text` is the best guess, `accepted` says whether to trust it,
    `words` are its words with their posteriors (when the recognizer knows them),
    `hypotheses` the N best transcripts, best first (when the recognizer gives them), and
    `reason` says why it was not accepted."""

    text: str
    confidence: float
    accepted: bool
    words: tuple[HeardWord, ...] = ()
    reason: str = ""
    hypotheses: tuple[Hypothesis, ...] = ()


NOTHING_HEARD = Recognition("", 0.0, False, reason="no speech")
# The reason of a recognition that is sure the speech is one of the grammar's decoys.
NOT_AN_ANSWER = "recognized as no answer"


class Recognizer(Protocol):
    def recognize(self, audio: Audio) -> Recognition: ...


def jsgf_grammar(phrases: Iterable[str], name: str = "answers") -> str:
    """A JSGF grammar whose one public rule is any of `phrases` (already normalized)."""
    alternatives = " | ".join(dict.fromkeys(phrases))
    if not alternatives:
        raise SpeechError("the recognizer needs at least one phrase")
    return f"#JSGF V1.0;\ngrammar {name};\npublic <utterance> = {alternatives};\n"


class GrammarRecognizer:
    """pocketsphinx with a phrase grammar, phone-loop verification and energy gating."""

    def __init__(
        self,
        phrases: Iterable[str],
        *,
        min_confidence: float = DEFAULT_MIN_CONFIDENCE,
        detector: SpeechDetector | None = None,
        decoys: Iterable[str] = DEFAULT_DECOYS,
        verify: bool = True,
        adaptation: Path | None = None,
    ) -> None:
        from pocketsphinx import Decoder, get_model_path

        self.phrases = frozenset(phrases)
        self.min_confidence = min_confidence
        self.detector = detector or SpeechDetector()
        # Without `verify` only the grammar, decoys and duration decide (about 3x faster:
        # no phone loop, and only the senones the grammar needs are scored); every
        # accepted phrase then has confidence 1.0.
        self.verify = verify
        model = Path(get_model_path())
        # compallsen: score every senone each frame, so the per-frame normalization (and
        # with it the ratio below) is the same for the grammar and the phone loop.
        self._decoder = Decoder(
            lm=None,
            loglevel="FATAL",
            compallsen=verify,
            samprate=float(SAMPLE_RATE),
            **adapted_to(adaptation),
        )
        missing = sorted(
            {w for p in self.phrases for w in p.split() if self._decoder.lookup_word(w) is None}
        )
        if missing:
            raise SpeechError(f"words missing from the pronunciation dictionary: {missing}")
        self.decoys = tuple(
            d
            for d in decoys
            if d not in self.phrases
            and all(self._decoder.lookup_word(w) is not None for w in d.split())
        )
        grammar = jsgf_grammar([*sorted(self.phrases), *self.decoys])
        self._decoder.add_jsgf_string("grammar", grammar)
        self._decoder.add_allphone_file("phones", str(model / "en-us" / "en-us-phone.lm.bin"))
        self._logmath = self._decoder.get_logmath()
        # One decoder, one utterance at a time.
        self._lock = threading.Lock()

    def recognize(self, audio: Audio) -> Recognition:
        segments = self.detector.segments(audio)
        if not segments:
            return NOTHING_HEARD
        with self._lock:
            whole = self._decode(audio)
            if whole.accepted or len(segments) < 2:
                return whole
            # Several sentences and the whole was not an answer: try the opening ones.
            total = len(audio.pcm) // SAMPLE_WIDTH
            best = whole
            for _, end in segments[:-1][:MAX_PREFIXES]:
                stop = min(total, end + _MARGIN_SAMPLES)
                prefix = self._decode(Audio(audio.pcm[: stop * SAMPLE_WIDTH]))
                if prefix.accepted and (not best.accepted or prefix.confidence > best.confidence):
                    best = prefix
            return best

    def _decode(self, audio: Audio) -> Recognition:
        grammar_score = self._score_per_frame("grammar", audio)
        hypothesis = self._decoder.hyp()
        text = hypothesis.hypstr if hypothesis is not None else ""
        decoy = text in self.decoys
        if grammar_score is None or not (decoy or text in self.phrases):
            return Recognition(text, 0.0, False, reason="not recognized")
        if self._too_slow(text, audio):
            return Recognition(text, 0.0, False, reason="not recognized")
        if not self.verify:
            return Recognition(text, 0.0 if decoy else 1.0, not decoy, reason=_reason(decoy))
        phone_score = self._score_per_frame("phones", audio)
        if phone_score is None:
            return Recognition(text, 0.0, False, reason="not recognized")
        ratio = grammar_score - phone_score
        confidence = round(1.0 / (1.0 + math.exp(-(ratio - RATIO_MIDPOINT) / RATIO_SCALE)), 3)
        sure = confidence >= self.min_confidence
        # A decoy heard with confidence is speech recognized as no answer: `reason` says so,
        # so a caller with a second recognizer knows not to try it.
        reason = _reason(decoy) if sure else "not recognized"
        return Recognition(text, confidence, sure and not decoy, reason=reason)

    def _too_slow(self, text: str, audio: Audio) -> bool:
        voiced = sum(end - start for start, end in self.detector.segments(audio)) / SAMPLE_RATE
        phones = sum(len((self._decoder.lookup_word(w) or "").split()) for w in text.split())
        return voiced > 0 and phones / voiced < MIN_PHONES_PER_SECOND

    def _score_per_frame(self, search: str, audio: Audio) -> float | None:
        decoder = self._decoder
        decoder.activate_search(search)
        with utterance(decoder):
            decoder.process_raw(audio.pcm, full_utt=True)
        hypothesis = decoder.hyp()
        frames = decoder.n_frames()
        if hypothesis is None or hypothesis.score <= 0.0 or frames == 0:
            return None
        # The binding hands the score back exponentiated; take the log again.
        return float(self._logmath.log(hypothesis.score)) / frames


def adapted_to(adaptation: Path | None) -> dict[str, str]:
    """The decoder options that apply an adaptation of the acoustic model: a file is an
    MLLR transform of its means (as sphinxtrain's `mllr_solve` writes it); a folder holds
    re-estimated parameters (`means`, `variances`, `sendump`, `transition_matrices`, as
    sphinxtrain's `map_adapt` and `mk_s2sendump` write them) that replace the model's own,
    each one present, and optionally an `mllr` transform as well."""
    if adaptation is None:
        return {}
    if adaptation.is_file():
        return {"mllr": str(adaptation)}
    if not adaptation.is_dir():
        raise SpeechError(f"no acoustic adaptation at {adaptation}")
    found = {
        option: str(adaptation / name)
        for option, name in _ADAPTED_PARAMETERS.items()
        if (adaptation / name).is_file()
    }
    if not found:
        names = ", ".join(_ADAPTED_PARAMETERS.values())
        raise SpeechError(f"{adaptation}: no adapted parameters (any of {names})")
    return found


# Decoder option -> file name, for an adaptation that is a folder.
_ADAPTED_PARAMETERS = {
    "mean": "means",
    "var": "variances",
    "sendump": "sendump",
    "tmat": "transition_matrices",
    "mllr": "mllr",
}


@contextmanager
def utterance(decoder: Any) -> Iterator[None]:
    """One utterance on a pocketsphinx decoder, ended even when processing raises: a
    decoder left mid-utterance refuses every later search ("Unable to set search")."""
    decoder.start_utt()
    try:
        yield
    finally:
        decoder.end_utt()


def _reason(decoy: bool) -> str:
    return NOT_AN_ANSWER if decoy else ""


class GoogleRecognizer:
    """Google's web speech API through SpeechRecognition (needs the network and
    `pip install SpeechRecognition`); its own confidence is used as is."""

    def __init__(self, language: str = "en-US") -> None:
        try:
            import speech_recognition
        except ImportError as err:
            raise SpeechError(
                "the google recognizer needs `pip install SpeechRecognition`"
            ) from err
        self._sr = speech_recognition
        self._recognizer = speech_recognition.Recognizer()
        self.language = language

    def recognize(self, audio: Audio) -> Recognition:
        if not SpeechDetector().has_speech(audio):
            return NOTHING_HEARD
        data = self._sr.AudioData(audio.pcm, SAMPLE_RATE, SAMPLE_WIDTH)
        try:
            result = self._recognizer.recognize_google(data, language=self.language, show_all=True)
        except self._sr.RequestError as err:
            raise SpeechError(f"Google speech recognition is unreachable: {err}") from err
        alternatives = result.get("alternative", []) if isinstance(result, dict) else []
        if not alternatives:
            return NOTHING_HEARD
        best = alternatives[0]
        confidence = float(best.get("confidence", 0.5))
        return Recognition(str(best.get("transcript", "")), confidence, True)
