"""The skill's replies in the request's language: one message catalog per locale.

`skill.prompts` is the en-US catalog and names every message; another locale's catalog is
`vahr/domain/locales/<locale>/replies.yaml`, the same names with the same placeholders.
`LocaleInterceptor` sets the request's locale (`request.locale`, as ASK skills read it)
with `use_locale`; from then on, for that request, `prompts.NAME` is the locale's message,
so the handlers keep writing `prompts.WELCOME` and need not know the language. A locale the
skill has no catalog for, or a name a catalog lacks, is spoken in English.
"""

from __future__ import annotations

import contextvars
import functools
import types
from typing import Any

from vahr.domain.locale import (
    DEFAULT_LOCALE,
    SUPPORTED_LOCALES,
    locale_file,
    read_yaml,
)

_locale: contextvars.ContextVar[str] = contextvars.ContextVar(
    "skill_locale", default=DEFAULT_LOCALE
)


def use_locale(locale: str | None) -> str:
    """Speak `locale` for the rest of this request (English when it has no catalog);
    returns the locale chosen."""
    chosen = locale if locale in SUPPORTED_LOCALES else DEFAULT_LOCALE
    _locale.set(chosen)
    return chosen


def current_locale() -> str:
    """The locale the current request is answered in."""
    return _locale.get()


@functools.cache
def replies(locale: str) -> dict[str, Any]:
    """The catalog of `locale` as written (en-US's is `skill.prompts` itself: empty here)."""
    if locale == DEFAULT_LOCALE:
        return {}
    catalog: dict[str, Any] = read_yaml(locale_file(locale, "replies.yaml"), dict[str, Any])
    return catalog


def _shaped(translated: Any, english: Any) -> Any:
    """`translated` in the shape of the English message: tuples where English has tuples."""
    if isinstance(english, tuple) and isinstance(translated, list):
        return tuple(_shaped(item, english[0] if english else None) for item in translated)
    if isinstance(english, dict) and isinstance(translated, dict):
        sample = next(iter(english.values()), None)
        return {key: _shaped(value, english.get(key, sample)) for key, value in translated.items()}
    return translated


# (locale, name) -> the message as spoken in that locale.
_messages: dict[tuple[str, str], Any] = {}


class _LocalisedModule(types.ModuleType):
    """A module whose upper-case names are messages, read in the request's locale."""

    def __getattribute__(self, name: str) -> Any:
        english = super().__getattribute__(name)
        locale = _locale.get()
        if locale == DEFAULT_LOCALE or not name.isupper():
            return english
        key = (locale, name)
        if key not in _messages:
            translated = replies(locale).get(name)
            _messages[key] = english if translated is None else _shaped(translated, english)
        return _messages[key]


def localise(module: types.ModuleType) -> None:
    """Make `module` (the en-US catalog) answer in the request's locale."""
    module.__class__ = _LocalisedModule
