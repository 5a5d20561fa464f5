"""The weather delivery's rule said aloud: which zone a person gave for which weather.

"Deliver to zone a if it's sunny and zone c if it's raining" fills the weather delivery's
`sunnyZone` and `rainyZone`. Each zone is paired with the weather said beside it: after the
zone when a zone comes first ("to zone a if it's sunny"), before it when a weather does ("if
it's raining go to zone c"), on its other side when its own says none; "otherwise zone c" is
the other weather, and "not sunny" is rainy. With no weather beside any zone ("to zone a or
zone c depending on the weather") the zones fill the rule in the order said, as Alexa fills
a sample's slots. A weather given two zones is heard but not resolved, so the skill turns
the rule down rather than guess. `states_a_weather_rule` tells a rule ("if it's raining, go
to zone c") from a report ("it's raining, go to zone c"), which names no rule at all.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from vahr.protocol.weather import PLAIN_NEGATIONS, WEATHER_WORDS
from vahr.skill_model.intents import RAINY_ZONE, SUNNY_ZONE

if TYPE_CHECKING:
    from vahr.local.alexa.slot_finder import SlotMatch

# The words that say which weather a zone of the weather delivery's rule is for.
_WEATHER_WORDS = {word: weather for weather, words in WEATHER_WORDS.items() for word in words}
_OTHER_WEATHER = frozenset({"otherwise", "else"})
# Words that make a weather a condition ("if it's sunny", "in case of rain", "a for sunny",
# "depending on the weather"), as a rule says it and a report ("it's raining, go to c")
# does not.
_CONDITIONS = frozenset({"if", "when", "case", "for", "unless", "depending", "according", "based"})
_RULE_VERBS = frozenset({"means", "goes", "go", "zone", "is"})
_NOT = frozenset(PLAIN_NEGATIONS)
RULE_SLOTS = {"sunny": SUNNY_ZONE.name, "rainy": RAINY_ZONE.name}


def rule_zones(zones: list[SlotMatch], words: list[str]) -> dict[str, SlotMatch]:
    """The rule's zones by the weather said beside each; a weather given two zones, or a
    zone with no weather, is heard but left unresolved for the skill to turn down."""
    said = [(at, _weather(words, at)) for at, word in enumerate(words) if word in _WEATHER_WORDS]
    if not zones:
        return {}
    weather_first = bool(said) and said[0][0] < zones[0].start
    kinds: list[str | None] = [
        _zone_weather(zones, rank, said, words, weather_first) for rank in range(len(zones))
    ]
    named = {kind for kind in kinds if kind in RULE_SLOTS}
    if not any(kinds):
        # No weather said beside any zone ("to zone a or zone c depending on the weather"):
        # the zones fill the rule in the order Alexa's samples give them, sunny first.
        kinds = [kind for kind, _ in zip(RULE_SLOTS, zones, strict=False)]
    elif len(named) == 1:
        (rest,) = RULE_SLOTS.keys() - named
        kinds = [rest if kind == "other" else kind for kind in kinds]
    filled: dict[str, SlotMatch] = {}
    for zone, kind in zip(zones, kinds, strict=True):
        slot = RULE_SLOTS.get(kind or "")
        if slot is None or slot in filled:
            slot = next((s for s in RULE_SLOTS.values() if s not in filled), None)
            if slot is None:
                continue
            zone = replace(zone, id=None, canonical=None)
        filled[slot] = zone
    return filled


def _weather(words: list[str], at: int) -> str:
    """The weather `words[at]` says, turned round by a "not" before it ("if it's not sunny")."""
    kind = _WEATHER_WORDS[words[at]]
    if _NOT & set(words[max(0, at - 2) : at]):
        return next(k for k in RULE_SLOTS if k != kind)
    return kind


def _zone_weather(
    zones: list[SlotMatch],
    rank: int,
    said: list[tuple[int, str]],
    words: list[str],
    weather_first: bool,
) -> str | None:
    """The weather zone `rank` is for: said on the sentence's side of it, "other" after
    "otherwise", else said on its other side ("zone a if it's sunny" after "if it's
    raining, zone c"); None when nothing says."""
    zone = zones[rank]
    before = range(zones[rank - 1].end if rank else 0, zone.start)
    after = range(zone.end, zones[rank + 1].start if rank + 1 < len(zones) else len(words))
    first, second = ((before, -1), (after, 0)) if weather_first else ((after, 0), (before, -1))
    near = [kind for at, kind in said if at in first[0]]
    if near:
        return near[first[1]]
    if rank and any(words[at] in _OTHER_WEATHER for at in [*before, *after]):
        return "other"
    near = [kind for at, kind in said if at in second[0]]
    return near[second[1]] if near else None


def states_a_weather_rule(words: list[str]) -> bool:
    """Whether the words make the weather a condition: a weather word with "if", "when",
    "for" or the like up to three words before it, or "means", "goes" or a zone right
    after it ("sunny zone a"); or "depending on the weather" and the like."""
    for at, word in enumerate(words):
        if word in _WEATHER_WORDS or word == "weather":
            if _CONDITIONS & set(words[max(0, at - 3) : at]):
                return True
            if words[at + 1 : at + 2] and words[at + 1] in _RULE_VERBS and word != "weather":
                return True
    return False
