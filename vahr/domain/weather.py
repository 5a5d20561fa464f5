"""The weather of the paper's task II: the weathers, the zone each one sends a robot to, and
the words people name them and deny them with.

The skill speaks the weather, robots hear it and deliver, the experiment draws and judges
it; all of them take these facts from here. The words are each locale's `language.yaml`
(`vahr.domain.locale`); the module's constants are English's, read on first use so that
importing the weathers costs no YAML. The skill's sample utterances and the simulator's
NLU name a weather with `WEATHER_WORDS`; the NLU and the robot's hearing deny one with
`NEGATIONS`. The robot's hearing decides by the cues of the assistant's answers
(`robot_agent/voice/weather_answers.yaml`: phrases such as "clear skies" and "cats and
dogs", weak and denied cues), which its recognizer and its tuning sets are built on.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from vahr.domain.locale import DEFAULT_LOCALE, load_language

if TYPE_CHECKING:
    from vahr.protocol.shadow import Weather

WEATHERS: tuple[Weather, ...] = ("sunny", "rainy")
# Deliver to A when it is sunny, to C when it is rainy (docs/protocol.md, Command).
WEATHER_ZONES: dict[Weather, str] = {"sunny": "A", "rainy": "C"}

if TYPE_CHECKING:
    # English's words (`__getattr__` below reads them from en-US's language.yaml).
    # The words a rule's condition is said with in the skill's sample utterances.
    SAMPLED_WEATHER_WORDS: dict[Weather, tuple[str, ...]]
    # Every word the simulator's NLU reads as naming a weather: those, and others people say.
    WEATHER_WORDS: dict[Weather, tuple[str, ...]]
    # A weather said just after one is the other ("if it's not sunny", "no rain").
    PLAIN_NEGATIONS: tuple[str, ...]
    # Every word that denies what follows it ("it won't rain", "leave the umbrella at home").
    NEGATIONS: tuple[str, ...]


def sampled_weather_words(locale: str = DEFAULT_LOCALE) -> dict[Weather, tuple[str, ...]]:
    """The words a rule's condition is said with in `locale`'s sample utterances."""
    sampled = load_language(locale).weather.sampled
    return {weather: tuple(sampled.get(weather, [])) for weather in WEATHERS}


def weather_words(locale: str = DEFAULT_LOCALE) -> dict[Weather, tuple[str, ...]]:
    """Every word that names each weather in `locale`: the sampled ones, then the others."""
    heard = load_language(locale).weather.heard
    return {
        weather: (*words, *heard.get(weather, []))
        for weather, words in sampled_weather_words(locale).items()
    }


def plain_negations(locale: str = DEFAULT_LOCALE) -> tuple[str, ...]:
    """The words after which a weather is the other one ("not sunny", "kein Regen")."""
    return tuple(load_language(locale).weather.plain_negations)


def negations(locale: str = DEFAULT_LOCALE) -> tuple[str, ...]:
    """Every word of `locale` that denies what follows it, the plain ones first."""
    return (*plain_negations(locale), *load_language(locale).weather.negations)


_ENGLISH = {
    "SAMPLED_WEATHER_WORDS": sampled_weather_words,
    "WEATHER_WORDS": weather_words,
    "PLAIN_NEGATIONS": plain_negations,
    "NEGATIONS": negations,
}


def __getattr__(name: str) -> Any:
    if name in _ENGLISH:
        return _ENGLISH[name]()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
