"""How sure the roles tagger is of which value fills which slot: the posterior of its label
sequence among the sequences the values' types allow, carried on the `Understanding`; a
reading below `ROLES_CONFIDENCE_THRESHOLD` is asked about, never acted on."""

from __future__ import annotations

import pytest

from vahr.assistant.evaluation import LabelledUtterance, outcome
from vahr.assistant.nlu import ROLES_CONFIDENCE_THRESHOLD, InteractionModel


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


@pytest.mark.parametrize(
    "utterance",
    [
        "send placebot one to zone b",
        "have placebot one deliver to zone c and then placebot two to zone d",
        "placebot one deliver to zone a or zone c depending on the weather",
    ],
)
def test_a_clear_sentence_is_read_surely(model: InteractionModel, utterance: str) -> None:
    understood = model.understand(utterance)
    assert understood.roles_confidence >= ROLES_CONFIDENCE_THRESHOLD
    assert understood.unsure_slots == ()
    assert not understood.needs_confirmation


def test_zones_with_no_word_for_their_weather_are_unsure(model: InteractionModel) -> None:
    # Nothing says which zone is for sunny weather and which for rain
    understood = model.understand("weather delivery for placebot one zone a zone c")
    assert understood.intent == "WeatherDeliveryIntent"
    assert understood.roles_confidence < ROLES_CONFIDENCE_THRESHOLD
    assert set(understood.unsure_slots) == {"sunnyZone", "rainyZone"}
    assert understood.needs_confirmation


def test_two_robots_and_two_zones_in_a_row_are_unsure(model: InteractionModel) -> None:
    understood = model.understand("placebot one placebot two zone c zone d deliver")
    assert understood.intent == "SequentialDeliveryIntent"
    assert understood.needs_confirmation


def test_the_posterior_is_among_the_allowed_sequences(model: InteractionModel) -> None:
    tagger = model.taggers["SequentialDeliveryIntent"]
    words, matches = model.find_slots("placebot one placebot two zone c zone d deliver")
    reading = tagger.read(words, matches)
    # Normalised over what the tagger may choose, each value's label is at least as sure as
    # the whole sequence, and no probability exceeds one.
    assert 0.0 < reading.confidence <= 1.0
    assert all(reading.confidence <= m <= 1.0 + 1e-9 for m in reading.marginals)
    assert reading.labels == tagger.labels(words, matches)


def test_an_unsure_reading_counts_as_asking_not_as_right_or_wrong(
    model: InteractionModel,
) -> None:
    text = "weather delivery for placebot one zone a zone c"
    expected = LabelledUtterance(
        text, "WeatherDeliveryIntent", {"robot": "placebot1", "sunnyZone": "A", "rainyZone": "C"}
    )
    said_otherwise = LabelledUtterance(
        text, "WeatherDeliveryIntent", {"robot": "placebot1", "sunnyZone": "C", "rainyZone": "A"}
    )
    understood = model.understand(text)
    assert outcome(model, expected, understood) == "asks"
    assert outcome(model, said_otherwise, understood) == "asks"
