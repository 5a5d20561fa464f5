"""The languages VAHR speaks, read from data: `locales/<locale>/language.yaml` beside this
module holds what the normaliser, the number speller and the weather words need of one
language, and `replies.yaml` the skill's message catalog in it.

`SUPPORTED_LOCALES` lists the locales shipped (a directory each; en-US is the default).
`load_language` reads one locale's words once per process; an unknown locale is one
`LocaleError` line naming the locales there are. Files are found with `os.path` (not
pathlib), as in `fleet`, since the skill's Lambda bundle carries this package.
"""

from __future__ import annotations

import functools
import os
from typing import Any, Literal

import msgspec

DEFAULT_LOCALE = "en-US"
LOCALES_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "locales")  # noqa: PTH100, PTH118, PTH120

# The weathers of the paper's task II (`vahr.domain.weather.Weather`).
_Weather = Literal["sunny", "rainy"]


class LocaleError(ValueError):
    """A locale that is not shipped, or a language file that cannot be read (a ValueError,
    as `ProtocolError` is: the skill's bundle carries no `vahr.errors`)."""


class Numbers(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """How numbers from 0 to 99 are said: `ones` 0-19, `tens` the multiples of ten (0-90,
    the first two unused), and `compound` how a ten and a one join ("{tens} {ones}" in
    English, "{ones}und{tens}" in German, where `compound_ones` says one is "ein").
    `variants` are other words for a number said as often ("zwo" for "zwei")."""

    ones: list[str]
    tens: list[str]
    compound: str = "{tens} {ones}"
    compound_ones: dict[int, str] = {}
    variants: dict[int, list[str]] = {}


class WeatherWords(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The words a weather is named and denied with.

    `sampled`: the words a rule's condition is said with in sample utterances; `heard`:
    more words people name a weather with; `plain_negations`: a weather said just after
    one is the other ("not sunny"); `negations`: every word that denies what follows it.
    """

    sampled: dict[_Weather, list[str]]
    heard: dict[_Weather, list[str]] = {}
    plain_negations: list[str] = []
    negations: list[str] = []


class Speech(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """How the local stack speaks and hears the language: the espeak-ng voice its replies
    are spoken with, and whether this machine can recognise it (its acoustic model)."""

    espeak_voice: str
    recognised: bool = False


class Invocation(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """How a request names the skill: "Alexa, ask robot fleet to ...", "Alexa, sage
    roboterflotte, ...". `ask` are the verbs before the invocation name with a request
    after it, `joiners` the words that may follow the name before the request, `open` the
    verbs that only open the skill (`open_joiners` join a request to them: "open robot fleet
    and ..."), and `trailing` the words before a name said last
    ("... using robot fleet")."""

    ask: list[str]
    joiners: list[str] = []
    open: list[str] = []
    open_joiners: list[str] = []
    trailing: list[str] = []


class Language(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One locale's `language.yaml`."""

    name: str
    invocation_name: str
    numbers: Numbers
    weather: WeatherWords
    speech: Speech
    invocation: Invocation
    # A first command in this language, with the fleet's names filled in (`vahr up`'s
    # banner suggests it): "send {robot} to {zone}".
    example_command: str = "send {robot} to {zone}"
    # What people call the whole fleet when the fleet file gives no group `all`.
    fleet_names: list[str] = msgspec.field(
        default_factory=lambda: ["all robots", "every robot", "everyone"]
    )

    def weather_words(self) -> dict[str, tuple[str, ...]]:
        """Every word that names each weather: the sampled words, then the heard ones."""
        return {
            weather: (*words, *self.weather.heard.get(weather, []))
            for weather, words in self.weather.sampled.items()
        }


def _shipped() -> tuple[str, ...]:
    try:
        entries = sorted(os.listdir(LOCALES_DIR))  # noqa: PTH208
    except OSError:
        return ()
    return tuple(
        entry
        for entry in entries
        if os.path.isfile(os.path.join(LOCALES_DIR, entry, "language.yaml"))  # noqa: PTH113, PTH118
    )


SUPPORTED_LOCALES: tuple[str, ...] = _shipped()


def check_locale(locale: str) -> str:
    """`locale` if it is shipped, else one `LocaleError` line listing those that are."""
    if locale not in SUPPORTED_LOCALES:
        raise LocaleError(f"unknown locale {locale!r}; supported: {', '.join(SUPPORTED_LOCALES)}")
    return locale


def locale_file(locale: str, name: str) -> str:
    """The path of `name` ("language.yaml", "replies.yaml") for a shipped locale."""
    return os.path.join(LOCALES_DIR, check_locale(locale), name)  # noqa: PTH118


def read_yaml(path: str, kind: Any) -> Any:
    """`path` decoded as `kind`, or one `LocaleError` line naming the file and the fault."""
    try:
        with open(path, "rb") as source:  # noqa: PTH123
            return msgspec.yaml.decode(source.read(), type=kind)
    except OSError as err:
        raise LocaleError(f"cannot read {path}: {err.strerror}") from err
    except msgspec.ValidationError as err:
        raise LocaleError(f"{path}: {err}") from err
    except msgspec.DecodeError as err:
        raise LocaleError(f"{path} is not valid YAML: {err}") from err


@functools.cache
def load_language(locale: str = DEFAULT_LOCALE) -> Language:
    """The words of `locale` (read once per process)."""
    return read_yaml(locale_file(locale, "language.yaml"), Language)  # type: ignore[no-any-return]
