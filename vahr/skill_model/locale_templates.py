"""The skill's intents in another language than en-US, from data.

en-US's templates are code (`intents`); every other locale's are
`locales/<locale>/templates.yaml` beside this module: shared phrases (`rules`), what a
person answers when asked for a slot of each type (`answers`), and each intent's
`essentials` and `templates`, keyed by the en-US intent's name. The slots are the en-US
intent's, so a locale is words only. `locale_intents` turns the file into the same
`IntentSpec`s the generator expands for en-US; an intent the file does not name is left
out of the locale's model (a test holds every locale to every intent).
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import msgspec

from vahr.errors import VahrError
from vahr.skill_model.intents import CUSTOM_INTENTS, MAX_SAMPLES_PER_INTENT, IntentSpec, SlotSpec

LOCALES_DIR = Path(__file__).resolve().parent / "locales"
_RULE = re.compile(r"<([a-z_]+)>")


class IntentTemplates(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One intent's samples kept whatever the draw, and its templates."""

    essentials: list[str] = []
    templates: list[str] = []


class LocaleTemplates(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One locale's `templates.yaml`."""

    answers: dict[str, list[str]]
    intents: dict[str, IntentTemplates]
    rules: dict[str, str] = {}


@dataclasses.dataclass(frozen=True)
class LocaleSlot(SlotSpec):
    """A slot whose elicitation answers are the locale's for its type."""

    spoken_answers: tuple[str, ...] = ()

    @property
    def answers(self) -> list[str]:
        return [answer.replace("{slot}", "{" + self.name + "}") for answer in self.spoken_answers]


def template_locales() -> tuple[str, ...]:
    """The locales other than en-US that have templates."""
    if not LOCALES_DIR.is_dir():
        return ()
    return tuple(sorted(d.name for d in LOCALES_DIR.iterdir() if (d / "templates.yaml").is_file()))


def load_templates(locale: str, directory: Path | None = None) -> LocaleTemplates:
    """The locale's templates file, or one `VahrError` line saying what is wrong."""
    file = (directory or LOCALES_DIR) / locale / "templates.yaml"
    if not file.is_file():
        raise VahrError(
            f"no templates for the locale {locale!r} (have: en-US, {', '.join(template_locales())})"
        )
    try:
        return msgspec.yaml.decode(file.read_bytes(), type=LocaleTemplates)
    except msgspec.ValidationError as err:
        raise VahrError(f"{file}: {err}") from err
    except msgspec.DecodeError as err:
        raise VahrError(f"{file} is not valid YAML: {err}") from err


def inline_rules(template: str, rules: dict[str, str], stack: tuple[str, ...] = ()) -> str:
    """`template` with each `<rule>` replaced by its template in parentheses."""

    def inline(found: re.Match[str]) -> str:
        name = found[1]
        if name not in rules:
            raise VahrError(f"template {template!r}: unknown rule <{name}>")
        if name in stack:
            raise VahrError(f"rule <{name}> refers to itself")
        return "(" + inline_rules(rules[name], rules, (*stack, name)) + ")"

    return _RULE.sub(inline, template)


def locale_intents(
    locale: str, base: tuple[IntentSpec, ...] = CUSTOM_INTENTS, directory: Path | None = None
) -> tuple[IntentSpec, ...]:
    """The en-US intents `base` with the locale's templates, essentials and answers."""
    data = load_templates(locale, directory)
    known = {intent.name for intent in base}
    for name in data.intents:
        if name not in known:
            raise VahrError(f"{locale} templates: {name!r} is not an intent of the skill")
    intents = []
    for intent in base:
        words = data.intents.get(intent.name)
        if words is None:
            continue
        slots = []
        for slot in intent.slots:
            if slot.type not in data.answers:
                raise VahrError(f"{locale} templates: no answers for the slot type {slot.type}")
            slots.append(LocaleSlot(slot.name, slot.type, tuple(data.answers[slot.type])))
        intents.append(
            dataclasses.replace(
                intent,
                slots=tuple(slots),
                essentials=tuple(words.essentials),
                templates=tuple(inline_rules(t, data.rules) for t in words.templates),
                # The locale's own templates, with the usual cap (an English intent's larger
                # cap is for English templates added later) or the English one when smaller.
                max_samples=min(intent.max_samples, MAX_SAMPLES_PER_INTENT),
            )
        )
    return tuple(intents)
