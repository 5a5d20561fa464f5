"""How the hearing decides from what a recognizer returned (`Hearing`): the
interpreter's meaning, held to the posteriors of the words it rests on when a minimum is
set, and nothing but the reason when the recognizer did not trust what it heard."""

from __future__ import annotations

import pytest

from robot_agent.voice.answers import WeatherAnswers
from robot_agent.voice.hearing import Hearing
from robot_agent.voice.interpreter import LocalInterpreter
from vahr.speech.stt import NOTHING_HEARD, HeardWord, Recognition


class Returns:
    """A recognizer that returns one recognition."""

    def __init__(self, recognition: Recognition) -> None:
        self.recognition = recognition

    def recognize(self, audio: object) -> Recognition:
        return self.recognition


def heard_as(*words: tuple[str, float]) -> Recognition:
    found = tuple(HeardWord(text, posterior) for text, posterior in words)
    return Recognition(
        " ".join(w.text for w in found), min(w.posterior for w in found), True, found
    )


@pytest.fixture(scope="module")
def interpreter() -> LocalInterpreter:
    return LocalInterpreter(WeatherAnswers.load())


# "it is not raining" heard as "it is now raining", with "now" barely ahead of "not"
DOUBTFUL = heard_as(("it", 0.9), ("is", 0.95), ("now", 0.4), ("raining", 0.99))


def test_by_default_the_meaning_decides_and_the_least_sure_word_is_the_confidence(
    interpreter: LocalInterpreter,
) -> None:
    heard = Hearing(Returns(DOUBTFUL), interpreter).hear(None)  # type: ignore[arg-type]
    assert (heard.intent, heard.confidence, heard.evidence) == ("rainy", 0.4, ("raining",))


def test_with_a_minimum_posterior_a_doubtful_deciding_word_is_unknown(
    interpreter: LocalInterpreter,
) -> None:
    hearing = Hearing(Returns(DOUBTFUL), interpreter, min_posterior=0.5)
    heard = hearing.hear(None)  # type: ignore[arg-type]
    assert heard.intent == "unknown"
    assert heard.reason == "unsure of the words that decide (0.40)"


def test_speech_the_recognizer_does_not_trust_is_unknown_with_no_text(
    interpreter: LocalInterpreter,
) -> None:
    doubted = Recognition("sunny", 0.1, False, reason="not recognized")
    for recognition, reason in (
        (NOTHING_HEARD, "no speech"),
        (doubted, "not recognized: 'sunny' (0.10)"),
    ):
        heard = Hearing(Returns(recognition), interpreter).hear(None)  # type: ignore[arg-type]
        assert (heard.text, heard.intent, heard.reason) == ("", "unknown", reason)
