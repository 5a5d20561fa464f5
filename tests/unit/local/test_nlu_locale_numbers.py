"""The simulator's NLU reads a number said as digits in its locale's words (from the
locale's language.yaml), so "roboter 2" in German is "roboter zwei", a name of robot two."""

from __future__ import annotations

from pathlib import Path

import pytest

from vahr.assistant.nlu import DEFAULT_MODEL, InteractionModel
from vahr.assistant.slot_finder import normalize_utterance
from vahr.assistant.understanding import load_understanding

GERMAN_MODEL = Path(DEFAULT_MODEL).with_name("de-DE.json")


@pytest.fixture(scope="module")
def german() -> InteractionModel:
    return InteractionModel.load(GERMAN_MODEL, understanding=load_understanding("de-DE"))


def test_digits_are_read_in_the_locales_words() -> None:
    assert normalize_utterance("Placebot 2, Zone B!") == "placebot two zone b"
    assert normalize_utterance("Placebot 2, Zone B!", "de-DE") == "placebot zwei zone b"
    # A locale without language data keeps its digits
    assert normalize_utterance("robo 2", "xx-XX") == "robo 2"


def test_a_german_robot_said_with_a_digit_is_heard_by_its_german_name(
    german: InteractionModel,
) -> None:
    understood = german.understand("roboter 2 fahr in die ladezone")
    robot = understood.slots["robot"]
    assert (understood.intent, robot.spoken, robot.id) == (
        "NavigateIntent",
        "roboter zwei",
        "placebot2",
    )
