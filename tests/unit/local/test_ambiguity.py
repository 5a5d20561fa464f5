"""A misheard name's alternatives: another value is offered when its name fits the misheard
word about as well as the chosen one, never when the word was heard as said or one name
fits clearly better; the margin is the one single-edit mishearings score best with."""

from __future__ import annotations

from vahr.assistant.ambiguity import CANDIDATE_MARGINS, SlotAmbiguity, calibrated_margin
from vahr.assistant.slot_finder import SlotTypeValues

ZONES = SlotTypeValues(
    "ZONE",
    {
        "zone mark": ("M", "zone mark"),
        "zone park": ("P", "zone park"),
        "zone delta": ("D", "zone delta"),
    },
)


def ambiguity() -> SlotAmbiguity:
    return SlotAmbiguity([ZONES], ["send", "to"])


def test_a_word_as_near_two_names_offers_the_other() -> None:
    # "bark" is as near "mark" as "park" (75 each): the finder's pick is a guess.
    found = ambiguity().alternatives(["zone", "bark"], ["zone", "mark"], (0, 2), "ZONE", "M")
    assert found == (("P", "zone park"),)


def test_a_word_clearly_nearer_one_name_offers_nothing() -> None:
    # "marks": 89 to "mark", 67 to "park".
    found = ambiguity().alternatives(["zone", "marks"], ["zone", "mark"], (0, 2), "ZONE", "M")
    assert found == ()


def test_a_name_heard_as_said_offers_nothing() -> None:
    found = ambiguity().alternatives(["zone", "mark"], ["zone", "mark"], (0, 2), "ZONE", "M")
    assert found == ()


def test_the_margin_is_one_of_the_candidates_and_grows_with_confusable_names() -> None:
    apart = calibrated_margin(("alpha", "bravo", "charlie", "delta"), frozenset())
    close = calibrated_margin(("marker", "parker", "barker", "darker"), frozenset())
    assert {apart, close} <= set(CANDIDATE_MARGINS)
    assert close >= apart
