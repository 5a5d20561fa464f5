"""Sample-utterance templates: alternatives, optional words and shared phrases, expanded.

The syntax is Home Assistant's (hassil's) sentence-template syntax, reduced to what an
Alexa sample needs: `(send|move)` picks one alternative, `[please]` may be left out,
`<polite>` inserts a shared rule (itself a template), and `{robot}` is a slot reference
kept as it is. Expansion is exhaustive and ordered, so the generated model is the same on
every run. `draw` picks sentences at random instead, for templates whose full expansion
would run to millions.
"""

from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING

from vahr.errors import VahrError

if TYPE_CHECKING:
    import random
    from collections.abc import Mapping


class TemplateError(VahrError):
    """A template that cannot be expanded: unbalanced brackets or an unknown rule."""


# A parsed part is a list of alternatives; an alternative is literal text or a sequence of
# parts.
_Part = list["str | list[_Part]"]

_CLOSING = {"(": ")", "[": "]"}


def expand(template: str, rules: Mapping[str, str] | None = None) -> list[str]:
    """Every sentence `template` stands for, words single-spaced, duplicates removed."""
    parts = _parse(template, rules or {}, ())
    seen: dict[str, None] = {}
    for sentence in _sentences(parts):
        seen.setdefault(" ".join(sentence.split()), None)
    return list(seen)


def draw(template: str, rules: Mapping[str, str], rng: random.Random, count: int) -> list[str]:
    """Up to `count` different sentences of `template`: all of them when it has no more,
    else distinct ones picked by walking the template with `rng` (reproducible by seed)."""
    parts = _parse(template, rules, ())
    if _size(parts) <= count:
        return expand(template, rules)
    chosen: dict[str, None] = {}
    # A walk may repeat a sentence already drawn; give up after a generous number of tries.
    for _ in range(count * 20):
        if len(chosen) >= count:
            break
        chosen.setdefault(" ".join(_walk(parts, rng).split()), None)
    return list(chosen)


def _parse(template: str, rules: Mapping[str, str], stack: tuple[str, ...]) -> _Part:
    parts, position = _sequence(template, 0, rules, stack, closing=None)
    if position != len(template):
        raise TemplateError(f"template {template!r}: unexpected {template[position]!r}")
    return [parts]


def _sequence(
    text: str, position: int, rules: Mapping[str, str], stack: tuple[str, ...], closing: str | None
) -> tuple[list[_Part], int]:
    """Parse up to `closing` (or `|` inside a group); returns the parts and where it stopped."""
    parts: list[_Part] = []
    literal = ""
    while position < len(text):
        char = text[position]
        if char in _CLOSING:
            parts.append([literal])
            literal = ""
            choices, position = _group(text, position, rules, stack)
            parts.append(choices)
            continue
        if char == "<":
            end = text.find(">", position)
            if end < 0:
                raise TemplateError(f"template {text!r}: '<' without '>'")
            name = text[position + 1 : end]
            if name not in rules:
                raise TemplateError(f"template {text!r}: unknown rule <{name}>")
            if name in stack:
                raise TemplateError(f"rule <{name}> refers to itself")
            parts.append([literal])
            literal = ""
            parts.append(_parse(rules[name], rules, (*stack, name)))
            position = end + 1
            continue
        if char in ")]|":
            if closing is None:
                raise TemplateError(f"template {text!r}: unexpected {char!r}")
            break
        literal += char
        position += 1
    else:
        if closing is not None:
            raise TemplateError(f"template {text!r}: missing {closing!r}")
    parts.append([literal])
    return parts, position


def _group(
    text: str, position: int, rules: Mapping[str, str], stack: tuple[str, ...]
) -> tuple[_Part, int]:
    """Parse `(a|b)` or `[a|b]` starting at `position`; an optional group may be empty."""
    opening = text[position]
    closing = _CLOSING[opening]
    choices: _Part = []
    position += 1
    while True:
        parts, position = _sequence(text, position, rules, stack, closing)
        choices.append(parts)
        if position >= len(text):
            raise TemplateError(f"template {text!r}: missing {closing!r}")
        if text[position] == "|":
            position += 1
            continue
        if text[position] != closing:
            raise TemplateError(f"template {text!r}: {text[position]!r} closes {opening!r}")
        break
    if opening == "[":
        choices.append("")
    return choices, position + 1


def _sentences(parts: _Part) -> list[str]:
    results: list[str] = []
    for alternative in parts:
        if isinstance(alternative, str):
            results.append(alternative)
            continue
        expansions = [_sentences(part) for part in alternative]
        results.extend("".join(words) for words in itertools.product(*expansions))
    return results


def _size(parts: _Part) -> int:
    """How many sentences `parts` stands for (duplicates counted)."""
    total = 0
    for alternative in parts:
        if isinstance(alternative, str):
            total += 1
        else:
            total += math.prod(_size(part) for part in alternative)
    return total


def _walk(parts: _Part, rng: random.Random) -> str:
    alternative = rng.choice(parts)
    if isinstance(alternative, str):
        return alternative
    return "".join(_walk(part, rng) for part in alternative)
