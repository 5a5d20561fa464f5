"""From the assistant's audio to a `Heard`: recognize, then interpret.

Speech the recognizer rejects (silence, noise, a sentence outside the expected answers)
is `unknown` with empty text: its in-grammar guess would only mislead whoever reads the
`heard` event.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from robot_agent.voice.port import Heard

if TYPE_CHECKING:
    from robot_agent.voice.interpreter import Interpreter
    from vahr.speech.audio import Audio
    from vahr.speech.stt import Recognizer

log = logging.getLogger(__name__)


class Understanding:
    """A recognizer and an interpreter used together."""

    def __init__(self, recognizer: Recognizer, interpreter: Interpreter) -> None:
        self.recognizer = recognizer
        self.interpreter = interpreter

    def hear(self, audio: Audio) -> Heard:
        recognition = self.recognizer.recognize(audio)
        if not recognition.accepted:
            log.debug("rejected %r (confidence %.3f)", recognition.text, recognition.confidence)
            return Heard("", "unknown", recognition.confidence)
        meaning = self.interpreter.interpret(recognition.text)
        if meaning.intent == "unknown":
            return Heard(recognition.text, "unknown", meaning.confidence)
        return Heard(
            recognition.text, meaning.intent, round(recognition.confidence * meaning.confidence, 3)
        )


def offline_understanding(answers_file: str | None = None) -> Understanding:
    """pocketsphinx and the local interpreter, both from `weather_answers.yaml`."""
    from pathlib import Path

    from robot_agent.voice.answers import ANSWERS_FILE, WeatherAnswers
    from robot_agent.voice.interpreter import LocalInterpreter
    from vahr.speech.stt import GrammarRecognizer

    answers = WeatherAnswers.load(Path(answers_file) if answers_file else ANSWERS_FILE)
    return Understanding(GrammarRecognizer(answers.all_phrases()), LocalInterpreter(answers))
