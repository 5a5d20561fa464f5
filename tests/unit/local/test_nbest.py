"""Weighing push-to-talk's N best with the shipped NLU: a reading that dominates is acted
on, a zone split between readings is asked about, and speech that is nothing the skill
does moves nothing."""

from __future__ import annotations

import pytest

from vahr.assistant.nbest import (
    MIN_SLOT_CONFIDENCE,
    Weighing,
    agreement,
    disputed,
    posteriors,
    request_reader,
    weigh,
)
from vahr.assistant.nlu import InteractionModel, Understanding
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.speech.stt import Hypothesis


@pytest.fixture(scope="module")
def understand() -> object:
    model = InteractionModel.load()

    def read(text: str) -> Understanding:
        return model.understand(text)

    return read


def test_posteriors_follow_the_scores_and_add_up_to_one() -> None:
    weights = posteriors([Hypothesis("a", -100.0), Hypothesis("b", -300.0)], 1 / 200)
    assert weights[0] > weights[1] and sum(weights) == pytest.approx(1.0)
    # 200 decoder units at sharpness 1/200 is a factor e between the two.
    assert weights[0] / weights[1] == pytest.approx(2.718, rel=1e-3)


def test_a_reading_that_dominates_is_acted_on(understand: object) -> None:
    weighed = weigh(
        [
            Hypothesis("send placebot one to zone c", 0.0),
            Hypothesis("send placebot one into zone c", -150.0),
            Hypothesis("send placebot one to zone d", -2000.0),
        ],
        understand,  # type: ignore[arg-type]
    )
    slots = weighed.understanding.slots
    assert weighed.understanding.intent == "NavigateIntent"
    assert (slots["robot"].id, slots["zone"].id) == ("placebot1", "C")
    assert not slots["zone"].alternatives
    assert weighed.slot_confidence["zone"] > 0.99


def test_a_zone_split_between_readings_is_asked_about(understand: object) -> None:
    weighed = weigh(
        [
            Hypothesis("send placebot two to zone d", 0.0),
            Hypothesis("send placebot two to zone b", -100.0),
            Hypothesis("please send placebot two to zone d", -200.0),
        ],
        understand,  # type: ignore[arg-type]
    )
    zone = weighed.understanding.slots["zone"]
    assert zone.id == "D" and zone.alternatives == (("B", "zone b"),)
    assert weighed.slot_confidence["robot"] == pytest.approx(1.0, abs=0.3)
    assert weighed.slot_confidence["zone"] < MIN_SLOT_CONFIDENCE


def test_with_higher_thresholds_a_split_robot_is_asked_about(understand: object) -> None:
    weighed = weigh(
        [
            Hypothesis("send placebot one to zone a", 0.0),
            Hypothesis("send placebot two to zone a", -60.0),
        ],
        understand,  # type: ignore[arg-type]
        Weighing(min_slot_confidence=0.9),
    )
    robot = weighed.understanding.slots["robot"]
    assert robot.id == "placebot1" and [v for v, _ in robot.alternatives] == ["placebot2"]


def test_a_zone_only_some_readings_hear_is_asked_for(understand: object) -> None:
    weighed = weigh(
        [
            Hypothesis("send placebot one to zone a", 0.0),
            Hypothesis("send placebot one to zone hey", -50.0),
            Hypothesis("send placebot one to the zone", -80.0),
        ],
        understand,  # type: ignore[arg-type]
    )
    # No rival zone was heard, so the skill is to ask for one ("To which zone?"), not be
    # handed "zone a" without its resolution (it would answer it knows no such zone)
    assert weighed.understanding.intent == "NavigateIntent"
    assert "zone" not in weighed.understanding.slots
    assert weighed.slot_confidence["zone"] < MIN_SLOT_CONFIDENCE
    assert weighed.understanding.slots["robot"].id == "placebot1"


@pytest.mark.parametrize(
    "readings",
    [
        ["play some music", "place some music", "play sunny music"],
        ["what is the capital of france", "what is the capital of the france"],
    ],
)
def test_speech_about_something_else_moves_nothing(understand: object, readings: list[str]) -> None:
    hypotheses = [Hypothesis(text, -50.0 * n) for n, text in enumerate(readings)]
    weighed = weigh(hypotheses, understand)  # type: ignore[arg-type]
    assert weighed.understanding.intent == FALLBACK_INTENT


def test_no_reading_at_all_is_the_fallback(understand: object) -> None:
    assert weigh([], understand).understanding.intent == FALLBACK_INTENT  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


def test_two_hearings_read_alike_are_acted_on(model: InteractionModel) -> None:
    # Written apart by two recognizers (punctuation and capitals are Whisper's), read alike
    both = agreement(model, "Send placebot one to zone C.", "send placebot one to zone c")
    assert both is not None and both.agreed
    assert both.understanding.intent == "NavigateIntent"
    assert {name: value.id for name, value in both.understanding.slots.items()} == {
        "robot": "placebot1",
        "zone": "C",
    }
    assert both.slot_confidence == {"robot": 1.0, "zone": 1.0}


@pytest.mark.parametrize(
    ("heard", "confirming"),
    [
        ("Send placebot one to zone G.", "send placebot one to zone d"),  # another zone
        ("Send placebot one to zone B.", "send placebot one to zone d"),  # the classic pair
        ("Send placebot two to zone D.", "send placebot one to zone d"),  # another robot
        ("Send placebot one to zone D.", "send placebot one"),  # the zone heard by one only
        ("What is a conveyor belt?", "what is a conveyor belt"),  # alike, but no request
    ],
)
def test_two_hearings_that_differ_in_what_moves_a_robot_are_weighed_instead(
    model: InteractionModel, heard: str, confirming: str
) -> None:
    assert agreement(model, heard, confirming) is None


@pytest.mark.parametrize(
    ("decided", "second", "asked"),
    [
        # The second ear heard zone B where the N best decided zone D: asked between the two
        ("send placebot one to zone d", "Send placebot one to zone B.", {"zone": ("D", ["B"])}),
        # ...or another robot: asked about the robot, the zone both heard stays
        ("send placebot one to zone d", "Send placebot two to zone D.",
         {"robot": ("placebot1", ["placebot2"])}),
        # The same values, another intent, or a value it did not hear: nothing asked
        ("send placebot one to zone d", "Send placebot one to zone D.", {}),
        ("send placebot one to zone d", "What is a conveyor belt?", {}),
        ("send placebot one to zone d", "Send placebot one.", {}),
    ],
)  # fmt: skip
def test_a_value_two_hearings_dispute_is_asked_about(
    model: InteractionModel, decided: str, second: str, asked: dict[str, object]
) -> None:
    read = request_reader(model)
    found = disputed(model, read(decided), read(second))
    questions = {
        name: (value.id, [rival for rival, _ in value.alternatives])
        for name, value in found.slots.items()
        if value.alternatives
    }
    assert questions == asked
    assert found.intent == read(decided).intent
