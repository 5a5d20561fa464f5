"""Interpretation: from recognized text to sunny, rainy or unknown.

`LocalInterpreter` works offline from the same sample phrasings the Lex bot is built from.
It accepts a sample said exactly, a sample said first with more words after it (the skill
may add a sentence after "The weather is sunny."), and near misses of a whole sample
(a word misheard by a free-form recognizer). Text that matches samples of both intents,
or nothing, is unknown.
"""

from __future__ import annotations

from dataclasses import dataclass
from difflib import SequenceMatcher
from typing import TYPE_CHECKING, Protocol

from vahr.speech.text import normalize

if TYPE_CHECKING:
    from robot_agent.voice.answers import WeatherAnswers
    from robot_agent.voice.port import WeatherIntent


@dataclass(frozen=True)
class Interpretation:
    intent: WeatherIntent
    confidence: float


class Interpreter(Protocol):
    def interpret(self, text: str) -> Interpretation:
        """Map recognized text to an intent; anything not understood is `unknown`."""
        ...


UNKNOWN = Interpretation("unknown", 0.0)
# The score of a whole sample found inside a longer text.
_WHOLE_SAMPLE = 0.8


class LocalInterpreter:
    """Matches text against the sample phrasings of `weather_answers.yaml`."""

    def __init__(self, answers: WeatherAnswers, *, min_similarity: float = 0.85) -> None:
        self.answers = answers
        self.min_similarity = min_similarity

    def interpret(self, text: str) -> Interpretation:
        spoken = normalize(text)
        if not spoken:
            return UNKNOWN
        words = spoken.split()
        best: dict[WeatherIntent, float] = {}
        for intent, samples in self.answers.phrases.items():
            for sample in samples:
                score = self._score(spoken, words, sample)
                if score > best.get(intent, 0.0):
                    best[intent] = score
        if not best:
            return UNKNOWN
        ranked = sorted(best.items(), key=lambda item: item[1], reverse=True)
        intent, score = ranked[0]
        # Both intents matched ("sunny now, rain later", or two near misses): do not guess.
        runner_up = ranked[1][1] if len(ranked) > 1 else 0.0
        if runner_up >= _WHOLE_SAMPLE or runner_up >= score - 0.05:
            return UNKNOWN
        return Interpretation(intent, round(score, 3))

    def _score(self, spoken: str, words: list[str], sample: str) -> float:
        if spoken == sample:
            return 1.0
        sample_words = sample.split()
        # The sample opens the answer, or is a whole sentence inside it.
        if _contains_sentence(words, sample_words):
            return 0.9 if words[: len(sample_words)] == sample_words else _WHOLE_SAMPLE
        similarity = SequenceMatcher(None, spoken, sample).ratio()
        return similarity * 0.9 if similarity >= self.min_similarity else 0.0


def _contains_sentence(words: list[str], sample: list[str]) -> bool:
    # Short samples ("sunny") would match inside unrelated sentences ("not sunny"):
    # only samples of two words or more count when embedded in a longer text.
    if len(sample) < 2 or len(sample) > len(words):
        return False
    return any(words[i : i + len(sample)] == sample for i in range(len(words) - len(sample) + 1))
