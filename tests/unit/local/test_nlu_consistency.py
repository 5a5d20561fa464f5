"""The check of a chosen intent against the slot values found, on a small model of its own."""

from __future__ import annotations

from vahr.assistant.consistency import SlotConsistency
from vahr.assistant.slot_finder import SlotMatch

INTENT_SLOTS = {
    "NavigateIntent": {"robot": "ROBOT", "zone": "ZONE"},
    "SequentialDeliveryIntent": {
        "firstRobot": "ROBOT",
        "firstZone": "ZONE",
        "secondRobot": "ROBOT",
        "secondZone": "ZONE",
    },
    "WeatherIntent": {},
    "AMAZON.HelpIntent": {},
}
SAMPLES = [
    ("NavigateIntent", "send {robot} to {zone}"),
    ("NavigateIntent", "move to {zone}"),
    ("SequentialDeliveryIntent", "{firstRobot} to {firstZone} then {secondRobot}"),
    ("SequentialDeliveryIntent", "start a sequential delivery"),
    ("WeatherIntent", "what is the weather"),
]


def named(*types: str) -> list[SlotMatch]:
    return [
        SlotMatch(t, i, i + 1, t.lower(), t.lower(), t.lower(), 100.0) for i, t in enumerate(types)
    ]


def test_an_intent_fits_the_value_counts_its_samples_show() -> None:
    check = SlotConsistency(INTENT_SLOTS, SAMPLES)
    assert check.agrees("NavigateIntent", named("ROBOT", "ZONE"))
    assert check.agrees("SequentialDeliveryIntent", named("ROBOT", "ZONE", "ROBOT"))
    assert check.agrees("SequentialDeliveryIntent", named())


def test_extra_values_of_a_type_are_left_to_the_slot_roles() -> None:
    # Two robots for one robot slot may be the fleet ("robot one and robot two").
    check = SlotConsistency(INTENT_SLOTS, SAMPLES)
    assert check.agrees("NavigateIntent", named("ROBOT", "ROBOT", "ZONE"))


def test_a_count_no_sample_shows_does_not_fit() -> None:
    check = SlotConsistency(INTENT_SLOTS, SAMPLES)
    assert not check.agrees("SequentialDeliveryIntent", named("ROBOT", "ZONE"))
    assert not check.agrees("NavigateIntent", named())


def test_an_intent_without_slots_fits_only_when_nothing_is_named() -> None:
    check = SlotConsistency(INTENT_SLOTS, SAMPLES)
    assert check.agrees("WeatherIntent", named())
    assert not check.agrees("WeatherIntent", named("ROBOT"))
    # Built-in intents have no samples in the model, and no slots either.
    assert not check.agrees("AMAZON.HelpIntent", named("ZONE"))
