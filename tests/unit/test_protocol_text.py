"""How spoken phrases are compared, and numbers spelled, everywhere (`vahr.domain.text`)."""

from __future__ import annotations

from vahr.domain.text import normalize, number_in_words, spell_numbers


def test_a_phrase_is_compared_in_lower_case_without_punctuation() -> None:
    # Given a written phrase, a slot value as Alexa hears a letter, and a typed apostrophe
    # Then each reads as the words a recognizer returns
    assert normalize("  It's SUNNY, today! ") == "it's sunny today"
    assert normalize("Zone B.") == "zone b"
    assert normalize("it\u2019s 'sunny'") == "it's sunny"


def test_numbers_are_spelled_as_they_are_said() -> None:
    assert [number_in_words(n) for n in (0, 12, 20, 42, 99, 100, -1)] == [
        "zero", "twelve", "twenty", "forty two", "ninety nine", None, None,
    ]  # fmt: skip
    assert spell_numbers("placebot2 to zone 12") == "placebot two to zone twelve"
    # a limit keeps larger numbers as digits (the NLU spells to twenty)
    assert spell_numbers("robot 21 to zone 20", below=21) == "robot 21 to zone twenty"
