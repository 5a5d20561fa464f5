"""The local interpreter and the answer definitions it shares with the Lex bot."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from robot_agent.voice.answers import WeatherAnswers, normalize
from robot_agent.voice.interpreter import LocalInterpreter
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from pathlib import Path


@pytest.fixture(scope="module")
def interpreter() -> LocalInterpreter:
    return LocalInterpreter(WeatherAnswers.load())


def test_the_shipped_answers_hold_the_skills_exact_sentences() -> None:
    # Given the file the CDK Lex bot is generated from
    answers = WeatherAnswers.load()
    # Then the skill's own answers are samples of the right intents
    assert answers.intent_of("The weather is sunny.") == "sunny"
    assert answers.intent_of("The weather is rainy.") == "rainy"
    assert len(answers.phrases["sunny"]) >= 4 and len(answers.phrases["rainy"]) >= 4


@pytest.mark.parametrize(
    ("text", "intent"),
    [
        ("The weather is sunny.", "sunny"),
        ("the weather is rainy", "rainy"),
        ("It's raining.", "rainy"),
        ("THE SUN IS SHINING!", "sunny"),
        # The skill may add a sentence after its answer.
        ("The weather is rainy. Anything else?", "rainy"),
        # A free-form recognizer's near miss of a whole sample.
        ("the weather is sunnny", "sunny"),
    ],
)
def test_samples_and_close_variants_are_understood(
    interpreter: LocalInterpreter, text: str, intent: str
) -> None:
    assert interpreter.interpret(text).intent == intent


@pytest.mark.parametrize(
    "text",
    ["", "   ", "what time is it", "the weather is cloudy", "please deliver to zone B",
     "it is sunny now but it will rain today"],
)  # fmt: skip
def test_anything_else_is_unknown(interpreter: LocalInterpreter, text: str) -> None:
    heard = interpreter.interpret(text)
    assert heard.intent == "unknown"
    assert heard.confidence == 0.0


def test_an_exact_sample_is_more_certain_than_a_near_miss(interpreter: LocalInterpreter) -> None:
    exact = interpreter.interpret("it is sunny today")
    near = interpreter.interpret("it is sunny to day")
    assert exact.confidence == 1.0
    assert 0.0 < near.confidence < exact.confidence


def test_normalize_drops_punctuation_and_case() -> None:
    assert normalize("  It\u2019s  SUNNY, today! ") == "it's sunny today"


@pytest.mark.parametrize(
    ("document", "reason"),
    [
        ("[]", "expected a mapping"),
        ("intents: {sunny: [a]}", "intents.rainy must be a non-empty list"),
        ("intents: {sunny: [a], rainy: [b], foggy: [c]}", "unknown intents ['foggy']"),
        ("intents: {sunny: [It is nice], rainy: [it is NICE]}", "listed under both"),
        ("intents: {sunny: ['!!'], rainy: [b]}", "empty phrase"),
        ("intents: [unclosed", "not valid YAML"),
    ],
)
def test_a_broken_answers_file_is_one_clear_error(
    tmp_path: Path, document: str, reason: str
) -> None:
    path = tmp_path / "answers.yaml"
    path.write_text(document)
    with pytest.raises(SpeechError, match=reason.replace("[", r"\[").replace("]", r"\]")):
        WeatherAnswers.load(path)
