"""From the assistant's audio to a `Heard`: recognize, interpret, and check that the
recognizer was sure of the words the decision rests on.

Two recognizers, the first exact and the second open:

1. a grammar of the sentences in `weather_answers.yaml`: the answers, and as decoys what
   is no answer. An answer it is sure of is interpreted; speech it is sure is one of the
   decoys ("it is cloudy", "thank you", robot talk) is `unknown` at once;
2. otherwise, a language model of the same sentences, which hears phrasings nobody
   listed ("it is pouring"). Its text is interpreted, and a decision stands only if every
   word it rests on (each cue, and the words before it where a negation would have stood)
   has a posterior of at least `min_posterior` in the recognizer's lattice: "no rain
   today" heard as "will rain today", with "will" barely ahead of "no", is `unknown`, and
   the executor asks again rather than deliver to the wrong zone.

Speech neither recognizer trusts (silence, noise, speech that does not sound like the
words they know) is `unknown` with empty text: a guess would only mislead whoever reads
the `heard` event. The reason says what happened.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING

from robot_agent.voice.port import Heard
from vahr.speech.stt import NOT_AN_ANSWER, NOTHING_HEARD

if TYPE_CHECKING:
    from robot_agent.voice.answers import WeatherAnswers
    from robot_agent.voice.interpreter import Interpretation, Interpreter
    from vahr.speech.audio import Audio
    from vahr.speech.stt import Recognition, Recognizer

log = logging.getLogger(__name__)

# Set on the tuning set only (robot_agent/voice/data/hearing-tuning.yaml): of 0, 0.3, 0.5,
# 0.7 and 0.9, the one with the most answers right less three times the unrelated speech
# accepted (a wrong delivery costs more than a question asked again). docs/voice.md.
DEFAULT_MIN_POSTERIOR = 0.3


class Understanding:
    """A recognizer and an interpreter used together, with an open recognizer to fall
    back on when the first one recognizes nothing."""

    def __init__(
        self,
        recognizer: Recognizer,
        interpreter: Interpreter,
        *,
        open_recognizer: Recognizer | None = None,
        min_posterior: float = DEFAULT_MIN_POSTERIOR,
    ) -> None:
        self.recognizer = recognizer
        self.interpreter = interpreter
        self.open_recognizer = open_recognizer
        self.min_posterior = min_posterior

    def hear(self, audio: Audio) -> Heard:
        recognition = self.recognizer.recognize(audio)
        if recognition.accepted:
            return self._decide(recognition)
        if self.open_recognizer is None or recognition.reason in (
            NOT_AN_ANSWER,
            NOTHING_HEARD.reason,
        ):
            return _rejected(recognition)
        wider = self.open_recognizer.recognize(audio)
        return self._decide(wider) if wider.accepted else _rejected(wider)

    def _decide(self, recognition: Recognition) -> Heard:
        meaning = self.interpreter.interpret(recognition.text)
        if meaning.intent == "unknown":
            return Heard(recognition.text, "unknown", 0.0, meaning.evidence, meaning.reason)
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


def recognizers(answers: WeatherAnswers) -> tuple[Recognizer, Recognizer]:
    """The exact recognizer (a grammar of the answers, the not-answers as decoys) and the
    open one (a language model of every sentence), both from `answers`, both adapted to
    the assistant's voice as `VAHR_HEARING_ADAPTATION` says."""
    from vahr.speech.lm_stt import LanguageModelRecognizer
    from vahr.speech.stt import DEFAULT_DECOYS, GrammarRecognizer

    adaptation = hearing_adaptation()
    decoys = (*answers.not_answers, *DEFAULT_DECOYS)
    exact = GrammarRecognizer(answers.all_phrases(), decoys=decoys, adaptation=adaptation)
    return exact, LanguageModelRecognizer(answers.corpus(), adaptation=adaptation)


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


def offline_understanding(answers_file: str | None = None) -> Understanding:
    """pocketsphinx (grammar, then language model) from `weather_answers.yaml`, and the
    local interpreter of its cues."""
    from robot_agent.voice.answers import ANSWERS_FILE, WeatherAnswers
    from robot_agent.voice.interpreter import LocalInterpreter

    answers = WeatherAnswers.load(Path(answers_file) if answers_file else ANSWERS_FILE)
    exact, wider = recognizers(answers)
    return Understanding(exact, LocalInterpreter(answers), open_recognizer=wider)
