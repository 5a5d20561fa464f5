"""The local interpreter and the answer definitions it shares with the recognizer and the
Lex bot: cues, negation, and what is no answer."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from robot_agent.voice.answers import WeatherAnswers
from robot_agent.voice.evaluation import EVALUATION_SET, TUNING_SET, Phrasings
from robot_agent.voice.interpreter import LocalInterpreter
from robot_agent.voice.sense import SENSE_FILE, training_sentences
from vahr.domain.text import normalize
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from pathlib import Path


@pytest.fixture(scope="module")
def answers() -> WeatherAnswers:
    return WeatherAnswers.load()


@pytest.fixture(scope="module")
def interpreter(answers: WeatherAnswers) -> LocalInterpreter:
    return LocalInterpreter(answers)


def test_the_shipped_answers_hold_the_skills_exact_sentences(answers: WeatherAnswers) -> None:
    # Given the file the recognizer, the interpreter and the CDK Lex bot are built from
    # Then the skill's own answers are samples of the right intents
    assert answers.intent_of("The weather is sunny.") == "sunny"
    assert answers.intent_of("The weather is rainy.") == "rainy"
    assert len(answers.phrases["sunny"]) >= 40 and len(answers.phrases["rainy"]) >= 40


def test_every_sample_is_understood_as_its_intent_and_every_not_answer_as_unknown(
    answers: WeatherAnswers, interpreter: LocalInterpreter
) -> None:
    wrong = [
        (sample, intent, interpreter.interpret(sample))
        for intent, samples in answers.phrases.items()
        for sample in samples
        if interpreter.interpret(sample).intent != intent
    ]
    wrong += [
        (sentence, "unknown", interpreter.interpret(sentence))
        for sentence in answers.not_answers
        if interpreter.interpret(sentence).intent != "unknown"
    ]
    assert wrong == []


@pytest.mark.parametrize("held_out", [EVALUATION_SET, TUNING_SET], ids=["eval", "tuning"])
def test_no_spoken_test_sentence_is_among_what_the_hearing_is_built_from(
    answers: WeatherAnswers, held_out: Path
) -> None:
    # Given the sentences the language model and the sense check are built from
    said, other = training_sentences(answers, SENSE_FILE)
    built_from = {*answers.corpus(), *said, *other}
    # Then none of the evaluation or tuning sentences is one of them
    assert Phrasings.load(held_out).normalized() & built_from == set()


def test_the_evaluation_and_tuning_sets_share_no_sentence_and_no_voice() -> None:
    evaluation, tuning = Phrasings.load(EVALUATION_SET), Phrasings.load(TUNING_SET)
    assert evaluation.normalized() & tuning.normalized() == set()
    assert set(evaluation.voices) & set(tuning.voices) == set()
    assert sum(len(texts) for texts in evaluation.answers.values()) >= 40
    assert len(evaluation.voices) == 3 and sorted(evaluation.snr_db) == [10, 20]


@pytest.mark.parametrize(
    ("text", "intent", "evidence"),
    [
        ("The weather is sunny.", "sunny", ("sunny",)),
        ("It's raining.", "rainy", ("raining",)),
        # Open phrasing: no sample says these.
        ("not a cloud in the sky", "sunny", ("not a cloud",)),
        ("it is pouring", "rainy", ("pouring",)),
        ("grey and wet all day", "rainy", ("wet",)),
        ("lovely and warm", "sunny", ("warm",)),
        # A denied cue says nothing; the other one decides.
        ("it is not raining it is sunny", "sunny", ("sunny",)),
        ("no sun today only rain", "rainy", ("rain",)),
        # The skill may add a sentence after its answer.
        ("the weather is rainy is there anything else", "rainy", ("rainy",)),
        # A weak cue gives way to the other weather's strong one ("right now" misheard).
        ("it is raining bright now", "rainy", ("raining",)),
        ("warm with heavy rain", "rainy", ("rain",)),
        ("bright and warm", "sunny", ("bright", "warm")),
        # So does a cue that counts only denied ("low clouds" heard as "no clouds").
        ("rainy and cool with no clouds", "rainy", ("rainy",)),
        # Leaving the umbrella at home denies the rain.
        ("leave the umbrella at home it is sunny", "sunny", ("sunny",)),
        # A verb without its subject opens no question: "it" was not heard.
        ("is raining right now", "rainy", ("raining",)),
        # Weather of another time says nothing of now.
        ("it is sunny now but it will rain next week", "sunny", ("sunny",)),
        # A weather named and taken back after it says nothing.
        ("it is raining so the sun will not be out today", "rainy", ("raining",)),
        ("good news it is sunny and the rain has stayed away", "sunny", ("sunny",)),
    ],
)
def test_cues_decide_and_are_reported(
    interpreter: LocalInterpreter, text: str, intent: str, evidence: tuple[str, ...]
) -> None:
    meaning = interpreter.interpret(text)
    assert (meaning.intent, meaning.evidence) == (intent, evidence)


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("", "nothing said"),
        ("what time is it", "a question (what ...)"),
        ("will it rain today", "a question (will ...)"),
        ("is it raining", "a question (is ...)"),
        ("the forecast says it will be sunny next tuesday", "the weather of another time"),
        ("it rained a lot last spring", "the weather of another time"),
        ("the sun sets at seven this evening", "the weather only denied"),
        ("no rain today", "the weather only denied"),
        ("it won't rain", "the weather only denied"),
        ("it is cloudy", "no weather word"),
        ("it is sunny now but it will rain later", "both sunny and rainy"),
        # Two weak cues, or two strong ones, still say both.
        ("bright but raining and sunny", "both sunny and rainy"),
        ("thank you it is sunny so i am delivering to zone a", "robot talk (delivering, zone)"),
    ],
)
def test_anything_else_is_unknown_with_the_reason(
    interpreter: LocalInterpreter, text: str, reason: str
) -> None:
    meaning = interpreter.interpret(text)
    assert (meaning.intent, meaning.confidence, meaning.reason) == ("unknown", 0.0, reason)


def test_the_decisive_words_are_the_cue_and_where_a_negation_could_stand(
    interpreter: LocalInterpreter,
) -> None:
    # "will" sits where "won't" would deny the rain; "it" opens the clause
    assert interpreter.interpret("it will rain today").decisive == (1, 2)
    assert interpreter.interpret("it is pouring").decisive == (1, 2)


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
        (
            "intents: {sunny: [a], rainy: [b]}\nnot_answers: [A]",
            "under both intents.sunny and not_answers",
        ),
        (
            "intents: {sunny: [a], rainy: [b]}\ncues: {foggy: [fog]}",
            "cues must map sunny and/or rainy",
        ),
        (
            "intents: {sunny: [a], rainy: [b]}\ncues: {sunny: [sun]}\nnegation_reach: 0",
            "negation_reach",
        ),
        (
            "intents: {sunny: [a], rainy: [b]}\ncues: {sunny: [sun]}\nnegations: [not]",
            "negations are vahr.domain.weather.NEGATIONS",
        ),
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
