"""From the assistant's audio to a `Heard`: recognize, interpret, and weigh how sure the
recognizer was of the words the decision rests on.

The offline hearing is one open recognizer: pocketsphinx with a language model of every
sentence in `weather_answers.yaml` (the answers, and what is no answer) and of the most
frequent words of English, on the acoustic model adapted to the assistant's voice
(`adaptation.py`). It hears phrasings nobody listed ("it is pouring"), and speech about
something else as what it is ("play the radio", not "play the rainy"). Its text is
interpreted, and the decision can be held to how sure the recognizer was of the words it
rests on (each cue, and the words before it where a negation would have stood): with a
`min_posterior`, "it is not raining" heard as "it is now raining", with "now" barely ahead
of "not" in the recognizer's lattice, is `unknown`, and the executor asks again rather than
deliver to the wrong zone. With the adapted model every such threshold cost more answers
than it saved unrelated speech on the tuning set, so by default there is none; the
posterior of the least sure deciding word is still the confidence reported.

A grammar of the listed answers used to be tried first, the language model only when the
grammar recognized nothing; with the adapted model, on the tuning set, the grammar's
confident matches of the wrong answer ("it's wet outside" as "it's sunny outside") cost
more than it gained, so the language model hears alone (docs/decisions/0002-robot-hearing.md
has the figures).

The interpreter reads cues, which say nothing of a word's sense ("a sunny personality"); so
offline, the sense check (`sense.py`) reads the whole sentence and may veto: what it finds
too unlikely an answer is `unknown`, whatever the cues.

Speech the recognizer does not trust (silence, noise) is `unknown` with empty text: a guess
would only mislead whoever reads the `heard` event. The reason says what happened.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING

from robot_agent.voice.port import Heard
from vahr.model_cache import default_cache_dir

if TYPE_CHECKING:
    from robot_agent.voice.answers import WeatherAnswers
    from robot_agent.voice.interpreter import Interpretation, Interpreter
    from robot_agent.voice.sense import SenseCheck
    from vahr.speech.audio import Audio
    from vahr.speech.stt import Recognition, Recognizer

log = logging.getLogger(__name__)

# Both set on the tuning set only (robot_agent/voice/data/hearing-tuning.yaml), as the
# value with the most answers right (mean of clean, 20 dB and 10 dB) less three times the
# unrelated speech accepted (a wrong delivery costs more than a question asked again).
# The minimum posterior, of 0, 0.01, 0.02, 0.05, 0.1, 0.2 and 0.3: 0, so with the adapted
# model the check stands aside (every threshold cost more answers than it saved unrelated
# speech); it stays a parameter for a voice heard less well. The commonest words the
# recognizer also knows, of 0, 3,000 and 10,000: 3,000. docs/decisions/0002-robot-hearing.md
# has the figures.
DEFAULT_MIN_POSTERIOR = 0.0
BACKGROUND_WORDS = 3000


class Hearing:
    """The robot's hearing: a recognizer and an interpreter used together, and optionally
    the sense check."""

    def __init__(
        self,
        recognizer: Recognizer,
        interpreter: Interpreter,
        *,
        min_posterior: float = DEFAULT_MIN_POSTERIOR,
        sense: SenseCheck | None = None,
    ) -> None:
        self.recognizer = recognizer
        self.interpreter = interpreter
        self.min_posterior = min_posterior
        self.sense = sense

    def hear(self, audio: Audio) -> Heard:
        recognition = self.recognizer.recognize(audio)
        return self._decide(recognition) if recognition.accepted else _rejected(recognition)

    def _decide(self, recognition: Recognition) -> Heard:
        meaning = self.interpreter.interpret(recognition.text)
        if meaning.intent == "unknown":
            return Heard(recognition.text, "unknown", 0.0, meaning.evidence, meaning.reason)
        sense = self.sense.read(recognition.text, meaning.sentence) if self.sense else None
        if sense is not None and not sense.is_answer:
            reason = f"reads as no answer ({sense.answer:.2f} an answer)"
            return Heard(recognition.text, "unknown", 0.0, meaning.evidence, reason)
        sureness = self._sureness(recognition, meaning)
        if sureness < self.min_posterior:
            doubt = f"unsure of the words that decide ({sureness:.2f})"
            return Heard(recognition.text, "unknown", sureness, meaning.evidence, doubt)
        confidence = round(min(sureness, recognition.confidence * meaning.confidence), 3)
        return Heard(recognition.text, meaning.intent, confidence, meaning.evidence)

    @staticmethod
    def _sureness(recognition: Recognition, meaning: Interpretation) -> float:
        """The lowest posterior among the words the decision rests on (1.0 when the
        recognizer gives none, e.g. a grammar, or the interpreter names none, e.g. Lex)."""
        words = recognition.words
        if not words or not meaning.decisive:
            return 1.0
        if max(meaning.decisive) >= len(words):
            return 0.0  # the interpreter read other words than were heard: do not trust
        return min(words[i].posterior for i in meaning.decisive)


def _rejected(recognition: Recognition) -> Heard:
    log.debug("rejected %r (%s)", recognition.text, recognition.reason)
    reason = recognition.reason or "not recognized"
    if recognition.text:
        reason = f"{reason}: {recognition.text!r} ({recognition.confidence:.2f})"
    return Heard("", "unknown", recognition.confidence, reason=reason)


def weather_recognizer(answers: WeatherAnswers, *, cache_dir: Path | None = None) -> Recognizer:
    """The offline recognizer: a language model of every sentence of `answers` and of the
    commonest English words, adapted to the assistant's voice as `VAHR_HEARING_ADAPTATION`
    says. The model comes from the trained models' cache (`cache_dir`, by default the
    user's) when it holds it: building it is most of the recognizer's start-up (0.85 s of CPU
    against 0.07 s from the cache, on a busy 2-core machine), which every robot of `vahr up`
    would otherwise spend at each start."""
    from vahr.speech.lm_stt import LanguageModelRecognizer, cached_language_model

    corpus = answers.corpus()
    model, cached = cached_language_model(
        corpus, BACKGROUND_WORDS, cache_dir=cache_dir or default_cache_dir()
    )
    log.debug("the hearing's language model was %s", "read from the cache" if cached else "built")
    return LanguageModelRecognizer(corpus, adaptation=hearing_adaptation(), model=model)


def hearing_adaptation(setting: str | None = None) -> Path | None:
    """The acoustic adaptation to hear the assistant with (`robot_agent/voice/adaptation.py`):
    `VAHR_HEARING_ADAPTATION` unset or `espeak-ng` is the bundled one, made for the local
    stack's espeak-ng assistant; `none` hears with pocketsphinx's model as it is (a human
    or an Alexa in the room); anything else is the path of a transform of one's own."""
    value = os.environ.get("VAHR_HEARING_ADAPTATION", "") if setting is None else setting
    if value in ("", "espeak-ng"):
        from robot_agent.voice.adaptation import BUNDLED

        return BUNDLED
    return None if value == "none" else Path(value)


def offline_hearing(answers_file: str | None = None) -> Hearing:
    """pocketsphinx with a language model of `weather_answers.yaml`, the local interpreter
    of its cues, and the sense check."""
    from robot_agent.voice.answers import ANSWERS_FILE, WeatherAnswers
    from robot_agent.voice.interpreter import LocalInterpreter
    from robot_agent.voice.sense import SenseCheck

    answers = WeatherAnswers.load(Path(answers_file) if answers_file else ANSWERS_FILE)
    return Hearing(
        weather_recognizer(answers), LocalInterpreter(answers), sense=SenseCheck.train(answers)
    )
