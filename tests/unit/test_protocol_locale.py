"""The languages from data: each locale's number words and weather words, English's as
they always were, and an unknown locale refused in one line naming the shipped ones."""

from __future__ import annotations

import logging

import pytest

from vahr.domain import Fleet, load_fleet, text, weather
from vahr.domain.fleet import spoken_in
from vahr.domain.locale import SUPPORTED_LOCALES, LocaleError, check_locale, load_language


def test_the_shipped_locales_are_english_and_german() -> None:
    assert SUPPORTED_LOCALES == ("de-DE", "en-US")
    assert load_language("de-DE").invocation_name == "roboterflotte"


def test_an_unknown_locale_is_one_line_naming_the_shipped_ones() -> None:
    with pytest.raises(LocaleError) as refused:
        check_locale("fr-FR")
    assert str(refused.value) == "unknown locale 'fr-FR'; supported: de-DE, en-US"


@pytest.mark.parametrize(
    ("number", "english", "german"),
    [
        (0, "zero", "null"),
        (1, "one", "eins"),
        (2, "two", "zwei"),
        (12, "twelve", "zwölf"),
        (21, "twenty one", "einundzwanzig"),
        (30, "thirty", "dreißig"),
        (47, "forty seven", "siebenundvierzig"),
        (100, None, None),
    ],
)
def test_numbers_are_said_as_each_language_says_them(
    number: int, english: str | None, german: str | None
) -> None:
    assert text.number_in_words(number) == english
    assert text.number_in_words(number, "de-DE") == german


def test_german_spells_numbers_and_keeps_its_letters() -> None:
    heard = text.normalize("Schick Placebot2 in Zone 3, bitte – schön!")
    assert heard == "schick placebot2 in zone 3 bitte schön"
    assert (
        text.spell_numbers(heard, locale="de-DE") == "schick placebot zwei in zone drei bitte schön"
    )
    assert text.number_variants(2, "de-DE") == ["zwo"]


def test_english_weather_words_are_unchanged_and_german_has_its_own() -> None:
    assert weather.SAMPLED_WEATHER_WORDS["sunny"] == ("sunny", "nice", "clear", "dry")
    assert "drizzle" in weather.WEATHER_WORDS["rainy"]
    assert weather.PLAIN_NEGATIONS == ("not", "isn't", "no")
    assert weather.NEGATIONS[:3] == ("not", "isn't", "no") and "leave" in weather.NEGATIONS
    assert "regnet" in weather.weather_words("de-DE")["rainy"]
    assert "nicht" in weather.plain_negations("de-DE")


def test_a_fleet_without_a_locales_names_falls_back_to_english_and_warns_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    # Given the bundled fleet without its German names
    bundled = load_fleet()
    english_only = Fleet.from_yaml(
        b"robots: [{thing: r1, spoken: [rover one], start: {x: 1, y: 1, theta: 0}}]\n"
        b"zones: [{id: LOADING, spoken: [loading zone], pose: {x: 3, y: 1, theta: 0}}]\n"
    )
    # When names are asked for in German
    with caplog.at_level(logging.WARNING, logger="vahr.domain.fleet"):
        robot = spoken_in(english_only.robots[0], "xx-XX")
        zone = spoken_in(english_only.zones[0], "xx-XX")
    # Then the English names serve, with one warning for the locale
    assert (robot, zone) == (["rover one"], ["loading zone"])
    assert [r.getMessage() for r in caplog.records] == [
        "fleet: 'r1' and maybe others have no xx-XX names (spoken_by_locale); their en-US "
        "names are used"
    ]
    # And a fleet that has them uses its own
    assert bundled.spoken_name("placebot2", "de-DE") == "placebot zwei"
