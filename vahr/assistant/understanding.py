"""What the simulator's NLU knows of a language beyond the interaction model, read from data.

Each locale has `locales/<locale>/understanding.yaml` beside this module (or in a directory
given to `load_understanding`):

- `built_in`: the phrases of Alexa's built-in intents (help, stop, cancel, ...), as
  templates; Alexa trains them on Amazon's own data, the simulator on these;
- `out_of_domain`: everyday requests the skill does not handle, as templates: they train
  `AMAZON.FallbackIntent`;
- `finder`: the few function words the slot finder reads around names (`joiners` that add a
  value to a list, `turns` that give a robot's place in a sequence, `going` verbs that may
  stand between a robot and its turn, and `other` phrases that name "the other" robot);
- `roles`: labelled sentences the roles tagger (`roles`) learns from beside the model's own
  samples, for what the samples do not show: values turned down ("from {-ZONE} to {zone}"),
  listed ("{robot} and {+robot}") or offered as a choice ("{robot} or {?robot}").

The templates use `vahr.skill_model.templates`' syntax. Nothing of a language is in code:
a new locale is a new directory (docs/guides/add-a-locale.md).
"""

from __future__ import annotations

from pathlib import Path

import msgspec

from vahr.errors import VahrError

LOCALES_DIR = Path(__file__).resolve().parent / "locales"
DEFAULT_LOCALE = "en-US"


class FinderWords(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """Function words the slot finder reads around slot values."""

    joiners: list[str] = []
    turns: dict[str, int] = {}
    going: list[str] = []
    other: list[str] = []
    articles: list[str] = []


class RoleExamples(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """Labelled templates for the roles tagger, for each of `intents`."""

    intents: list[str]
    examples: list[str]


class LanguageUnderstanding(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One locale's `understanding.yaml`."""

    built_in: dict[str, list[str]] = {}
    out_of_domain: list[str] = []
    # What leaves an open session at once, as on an Echo ("exit", "goodbye").
    exits: list[str] = []
    finder: FinderWords = FinderWords()
    roles: list[RoleExamples] = []
    # The locale the file is for (set by `load_understanding`, not written in the file): the
    # roles tagger reads the locale's weather words from its `language.yaml`.
    locale: str = DEFAULT_LOCALE


def understanding_file(locale: str, directory: Path | None = None) -> Path:
    return (directory or LOCALES_DIR) / locale / "understanding.yaml"


def load_understanding(
    locale: str = DEFAULT_LOCALE, directory: Path | None = None
) -> LanguageUnderstanding:
    """The locale's understanding data, or one `VahrError` line saying what is wrong."""
    file = understanding_file(locale, directory)
    if not file.is_file():
        shipped = sorted(p.name for p in (directory or LOCALES_DIR).iterdir() if p.is_dir())
        raise VahrError(
            f"no understanding data for the locale {locale!r} (have: {', '.join(shipped)})"
        )
    try:
        understanding = msgspec.yaml.decode(file.read_bytes(), type=LanguageUnderstanding)
    except msgspec.ValidationError as err:
        raise VahrError(f"{file}: {err}") from err
    except msgspec.DecodeError as err:
        raise VahrError(f"{file} is not valid YAML: {err}") from err
    return msgspec.structs.replace(understanding, locale=locale)
