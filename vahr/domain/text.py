"""How spoken phrases are compared: lower case, punctuation dropped, single spaces, and
numbers written as words where words are compared with words.

Every reader of speech passes text through `normalize`, so a phrase written "It's sunny."
in a file is the phrase a recognizer returns as "it's sunny", and a slot value Alexa heard
as "zone b." is the fleet's "zone b": the skill (slot values against the fleet's names),
the simulator's NLU, the station's push-to-talk sentences and the robot's hearing
(grammars, recognized text, sample phrasings). Letters of any language are kept ("zwölf",
"straße"). `spell_numbers` writes numbers as people say them in a locale ("placebot 2" ->
"placebot two", in de-DE "placebot zwei"); the number words are the locale's
`language.yaml` (`vahr.domain.locale`), read the first time a number is spelled. Plain
`re`, as the skill's Lambda bundle carries this package.
"""

from __future__ import annotations

import re

from vahr.domain.locale import DEFAULT_LOCALE, load_language

# Anything but a letter (of any alphabet), a digit, an apostrophe or a space.
_NOT_WORD = re.compile(r"[^\w' ]+|_")
_LETTER_DIGIT = re.compile(r"(?<=[^\W\d_])(?=\d)|(?<=\d)(?=[^\W\d_])")
_DIGITS = re.compile(r"\d+")


def normalize(text: str) -> str:
    """Lower case, punctuation removed (an apostrophe kept inside a word), single spaces:
    "It’s sunny." -> "it's sunny"."""
    cleaned = _NOT_WORD.sub(" ", text.lower().replace("\u2019", "'"))
    return " ".join(word for word in (part.strip("'") for part in cleaned.split()) if word)


def number_in_words(number: int, locale: str = DEFAULT_LOCALE) -> str | None:
    """`number` as it is said in `locale`, for 0 to 99 ("forty two", "zweiundvierzig");
    None for any other."""
    if not 0 <= number < 100:
        return None
    words = load_language(locale).numbers
    if number < 20:
        return words.ones[number]
    tens, ones = divmod(number, 10)
    if not ones:
        return words.tens[tens]
    one = words.compound_ones.get(ones, words.ones[ones])
    return words.compound.format(tens=words.tens[tens], ones=one)


def number_variants(number: int, locale: str = DEFAULT_LOCALE) -> list[str]:
    """Other words `locale` says `number` with as often as its own ("zwo" for two)."""
    return list(load_language(locale).numbers.variants.get(number, []))


def spell_numbers(text: str, *, below: int = 100, locale: str = DEFAULT_LOCALE) -> str:
    """Each whole number in normalized `text` under `below` written as words of `locale`,
    split from letters it is joined to: "placebot2 to zone 12" -> "placebot two to zone
    twelve"."""

    if _DIGITS.search(text) is None:
        # Both patterns need a digit: the text is only re-spaced (one search, not two
        # substitutions; the station's language model spells 185,000 sentences at a start).
        return " ".join(text.split())

    def spelled(found: re.Match[str]) -> str:
        number = int(found[0])
        words = number_in_words(number, locale) if number < below else None
        return words or found[0]

    return " ".join(_DIGITS.sub(spelled, _LETTER_DIGIT.sub(" ", text)).split())
