"""The Alexa simulator in a locale: its interaction model and understanding data, and the
phrasings that address the skill by its invocation name.

`load_model("de-DE")` is the NLU built from `interactionModels/custom/de-DE.json` and
`locales/de-DE/understanding.yaml`; `invocation_patterns` and `strip_invocation` read the
locale's `language.yaml` (`vahr.domain.locale`): "Alexa, ask robot fleet to ..." in
English, "Alexa, sage Roboterflotte, ..." in German. An unknown locale is one line naming
the supported ones.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

from vahr.assistant.nlu import DEFAULT_MODEL, InteractionModel, normalize_utterance
from vahr.assistant.understanding import load_understanding
from vahr.domain.locale import DEFAULT_LOCALE, LocaleError, check_locale, load_language
from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path


def supported(locale: str) -> str:
    """`locale`, or a `VahrError` line naming the locales shipped."""
    try:
        return check_locale(locale)
    except LocaleError as err:
        raise VahrError(str(err)) from err


def model_file(locale: str = DEFAULT_LOCALE) -> Path:
    """The shipped interaction model of `locale`."""
    return DEFAULT_MODEL.with_name(f"{supported(locale)}.json")


def load_model(
    locale: str = DEFAULT_LOCALE, path: Path | None = None, **options: Any
) -> InteractionModel:
    """The simulator's NLU for `locale`: its interaction model (`path`, or the shipped one)
    and its understanding data."""
    understanding = load_understanding(supported(locale))
    return InteractionModel.load(path or model_file(locale), understanding=understanding, **options)


def _either(words: list[str]) -> str:
    return "|".join(r"\s+".join(map(re.escape, word.split())) for word in words)


def invocation_patterns(
    invocation_name: str, locale: str = DEFAULT_LOCALE
) -> tuple[re.Pattern[str], re.Pattern[str]]:
    """(a request with the invocation, the skill opened alone) for normalized text:
    "alexa ask robot fleet to <rest>" and "alexa open robot fleet" in English."""
    words = load_language(locale).invocation
    name = re.escape(normalize_utterance(invocation_name))
    one_shot = re.compile(
        rf"^(?:alexa\s+)?(?:{_either(words.ask)})\s+{name}(?:\s+(?:{_either(words.joiners)}))?"
        rf"(?:\s+(?P<rest>.*))?$"
    )
    opening = re.compile(rf"^(?:alexa\s+)?(?:{_either(words.open)})\s+{name}$")
    return one_shot, opening


def strip_invocation(invocation_name: str, utterance: str, locale: str = DEFAULT_LOCALE) -> str:
    """What is said to the skill once the wake word and invocation are removed, in the
    phrasings the locale addresses a skill with ("Alexa, sage Roboterflotte, schicke ...",
    "... mit Roboterflotte")."""
    words = load_language(locale).invocation
    text = normalize_utterance(utterance).removeprefix("alexa ")
    name = normalize_utterance(invocation_name)
    text = text.removeprefix(name + " ")
    one_shot, _ = invocation_patterns(invocation_name, locale)
    found = one_shot.match(text)
    if found:
        return found["rest"] or ""
    opened = re.match(
        rf"^(?:{_either(words.open)})\s+{re.escape(name)}\s+(?:{_either(words.open_joiners)})"
        rf"(?:\s+(?P<rest>.*))?$",
        text,
    )
    if opened:
        return opened["rest"] or ""
    trailing = re.match(
        rf"^(?P<rest>.+?)\s+(?:{_either(words.trailing)})\s+{re.escape(name)}$", text
    )
    return trailing["rest"] if trailing else text
