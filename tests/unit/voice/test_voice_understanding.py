"""How the hearing decides from what a recognizer returned (`Understanding`): the
interpreter's meaning, held to the posteriors of the words it rests on when a minimum is
set, and the open recognizer tried only when the first one recognized nothing."""

from __future__ import annotations

import pytest

from robot_agent.voice.answers import WeatherAnswers
from robot_agent.voice.interpreter import LocalInterpreter
from robot_agent.voice.understanding import Understanding
from vahr.speech.stt import NOT_AN_ANSWER, NOTHING_HEARD, HeardWord, Recognition


class Returns:
    """A recognizer that returns one recognition, and counts how often it was asked."""

    def __init__(self, recognition: Recognition) -> None:
        self.recognition = recognition
        self.calls = 0

    def recognize(self, audio: object) -> Recognition:
        self.calls += 1
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
    heard = Understanding(Returns(DOUBTFUL), interpreter).hear(None)  # type: ignore[arg-type]
    assert (heard.intent, heard.confidence, heard.evidence) == ("rainy", 0.4, ("raining",))


def test_with_a_minimum_posterior_a_doubtful_deciding_word_is_unknown(
    interpreter: LocalInterpreter,
) -> None:
    hearing = Understanding(Returns(DOUBTFUL), interpreter, min_posterior=0.5)
    heard = hearing.hear(None)  # type: ignore[arg-type]
    assert heard.intent == "unknown"
    assert heard.reason == "unsure of the words that decide (0.40)"


def test_the_open_recognizer_is_asked_only_when_the_first_recognized_nothing(
    interpreter: LocalInterpreter,
) -> None:
    sure_no_answer = Recognition("thank you", 0.95, False, reason=NOT_AN_ANSWER)
    nothing = Recognition("sunny", 0.1, False, reason="not recognized")
    pouring = heard_as(("it", 0.9), ("is", 0.9), ("pouring", 0.95))
    for first, expected, asked in (
        (sure_no_answer, "unknown", 0),
        (NOTHING_HEARD, "unknown", 0),
        (nothing, "rainy", 1),
    ):
        wider = Returns(pouring)
        heard = Understanding(Returns(first), interpreter, open_recognizer=wider).hear(None)  # type: ignore[arg-type]
        assert (heard.intent, wider.calls) == (expected, asked), first
