"""How spoken phrases are compared: lower case, punctuation dropped, single spaces, and
numbers written as words where words are compared with words.

Every reader of speech passes text through `normalize`, so a phrase written "It's sunny."
in a file is the phrase a recognizer returns as "it's sunny", and a slot value Alexa heard
as "zone b." is the fleet's "zone b": the skill (slot values against the fleet's names),
the simulator's NLU, the station's push-to-talk sentences and the robot's hearing
(grammars, recognized text, sample phrasings). `spell_numbers` writes numbers as people
say them ("placebot 2" -> "placebot two"). Plain `re`, as the skill's Lambda bundle
carries this package.
"""

from __future__ import annotations

import re

_NOT_WORD = re.compile(r"[^a-z0-9' ]+")
_LETTER_DIGIT = re.compile(r"(?<=[a-z])(?=\d)|(?<=\d)(?=[a-z])")
_DIGITS = re.compile(r"\d+")
_ONES = (
    "zero one two three four five six seven eight nine ten eleven twelve thirteen fourteen "
    "fifteen sixteen seventeen eighteen nineteen"
).split()
_TENS = "_ _ twenty thirty forty fifty sixty seventy eighty ninety".split()


def normalize(text: str) -> str:
    """Lower case, punctuation removed (an apostrophe kept inside a word), single spaces:
    "It’s sunny." -> "it's sunny"."""
    cleaned = _NOT_WORD.sub(" ", text.lower().replace("\u2019", "'"))
    return " ".join(word.strip("'") for word in cleaned.split() if word.strip("'"))


def number_in_words(number: int) -> str | None:
    """`number` as it is said, for 0 to 99 ("forty two"); None for any other."""
    if not 0 <= number < 100:
        return None
    if number < 20:
        return _ONES[number]
    tens, ones = divmod(number, 10)
    return _TENS[tens] + (f" {_ONES[ones]}" if ones else "")


def spell_numbers(text: str, *, below: int = 100) -> str:
    """Each whole number in normalized `text` under `below` written as words, split from
    letters it is joined to: "placebot2 to zone 12" -> "placebot two to zone twelve"."""

    def spelled(found: re.Match[str]) -> str:
        number = int(found[0])
        words = number_in_words(number) if number < below else None
        return words or found[0]

    return " ".join(_DIGITS.sub(spelled, _LETTER_DIGIT.sub(" ", text)).split())
