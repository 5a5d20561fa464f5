"""The sense check: a sentence with a weather word is an answer only if it is about the
weather; the classifier behind it answers as scikit-learn does, from a cache."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from robot_agent.voice.answers import WeatherAnswers
from robot_agent.voice.hearing import Hearing
from robot_agent.voice.interpreter import LocalInterpreter
from robot_agent.voice.sense import SENSE_FILE, SenseCheck, features, training_sentences
from vahr.speech.errors import SpeechError
from vahr.speech.stt import HeardWord, Recognition
from vahr.speech.text_classifier import TextClassifier, export, fit

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.speech.audio import Audio


@pytest.fixture(scope="module")
def answers() -> WeatherAnswers:
    return WeatherAnswers.load()


@pytest.fixture(scope="module")
def sense(answers: WeatherAnswers, tmp_path_factory: pytest.TempPathFactory) -> SenseCheck:
    return SenseCheck.train(answers, cache_dir=tmp_path_factory.mktemp("cache"))


class _Heard:
    """A recognizer that hears a fixed sentence."""

    def __init__(self, text: str) -> None:
        self.text = text

    def recognize(self, audio: Audio) -> Recognition:
        words = tuple(HeardWord(word, 1.0) for word in self.text.split())
        return Recognition(self.text, 1.0, True, words)


@pytest.mark.parametrize(
    "text", ["it is pouring", "grey and wet all day", "lovely and warm", "the weather is sunny"]
)
def test_answers_in_open_phrasing_read_as_answers(sense: SenseCheck, text: str) -> None:
    assert sense.read(text).is_answer, sense.read(text)


@pytest.mark.parametrize(
    "text",
    [
        "my sister has a very sunny temper",
        "we should buy shares in the umbrella maker",
        "the shower in the second bathroom is broken",
        "i left my umbrella at home yesterday but that does not matter",
    ],
)
def test_weather_words_in_another_sense_do_not(sense: SenseCheck, text: str) -> None:
    assert not sense.read(text).is_answer, sense.read(text)


def test_a_cue_in_another_sense_is_heard_as_no_answer(
    answers: WeatherAnswers, sense: SenseCheck
) -> None:
    # Given the offline hearing with the sense check, hearing a sentence whose cue
    # ("shower") is not about the weather
    heard = _Heard("the shower in the second bathroom is broken")
    hearing = Hearing(heard, LocalInterpreter(answers), sense=sense)
    # When it decides
    result = hearing.hear(None)  # type: ignore[arg-type]
    # Then it is unknown, the cue reported, and the reason says why
    assert result.intent == "unknown"
    assert result.evidence == ("shower",)
    assert result.reason.startswith("reads as no answer")
    # And without the check the cue alone would have decided
    alone = Hearing(heard, LocalInterpreter(answers)).hear(None)  # type: ignore[arg-type]
    assert alone.intent == "rainy"


def test_the_model_is_cached_and_answers_the_same(
    answers: WeatherAnswers, sense: SenseCheck, tmp_path: Path
) -> None:
    first = SenseCheck.train(answers, cache_dir=tmp_path)
    assert list(tmp_path.glob("answer-sense-*.json"))
    again = SenseCheck.train(answers, cache_dir=tmp_path)
    for text in ("it is pouring", "a sunny temper"):
        assert first.read(text) == again.read(text) == sense.read(text)


def test_the_export_gives_sklearns_probabilities_for_two_classes(answers: WeatherAnswers) -> None:
    # Given the binary pipeline and its plain-number export
    said, other = training_sentences(answers, SENSE_FILE)
    texts, labels = [*said, *other], ["answer"] * len(said) + ["other"] * len(other)
    pipeline = fit(texts, labels, features)
    exported = TextClassifier(export(pipeline), features)
    # When both score sentences seen and unseen
    probes = [*texts[::50], "qwerty", "it is sunny in the kitchen"]
    expected = pipeline.predict_proba(probes)
    # Then they agree to rounding error
    for probe, row in zip(probes, expected, strict=True):
        got = dict(exported.scores(probe).ranked)
        for name, probability in zip(pipeline.classes_, row, strict=True):
            assert got[str(name)] == pytest.approx(probability, abs=1e-9), (probe, name)


def test_a_broken_sense_file_is_one_clear_error(answers: WeatherAnswers, tmp_path: Path) -> None:
    broken = tmp_path / "sense.yaml"
    broken.write_text("answers: [it is sunny]\n")
    with pytest.raises(SpeechError, match="expected lists 'answers' and 'other'"):
        training_sentences(answers, broken)
    with pytest.raises(SpeechError, match="cannot read"):
        training_sentences(answers, tmp_path / "missing.yaml")


def test_an_answer_followed_by_the_assistants_question_is_still_an_answer(
    answers: WeatherAnswers, sense: SenseCheck
) -> None:
    # Given the skill's answer and the question it goes on with, heard as one text
    heard = _Heard("the weather is rainy is there anything else i can help with")
    hearing = Hearing(heard, LocalInterpreter(answers), sense=sense)
    # Then the answer is read in the sentence its cue was said in
    assert LocalInterpreter(answers).interpret(heard.text).sentence == "the weather is rainy"
    assert hearing.hear(None).intent == "rainy"  # type: ignore[arg-type]
