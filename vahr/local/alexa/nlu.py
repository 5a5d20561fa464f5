"""Natural-language understanding built from the skill's interaction model.

Each sample utterance becomes a pattern (its `{slot}` references capture words); an
utterance is matched against every pattern and the best match wins: first the one whose
slot values all resolve against their slot types, then the most specific (the most literal
words). Slot values resolve against the custom slot types' values and synonyms, giving
Alexa's entity-resolution outcome (ER_SUCCESS_MATCH with the value's id and name, or
ER_SUCCESS_NO_MATCH). Built-in intents get Alexa's usual phrases; anything else is
AMAZON.FallbackIntent.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from vahr.errors import VahrError

# The interaction model ships with the package (in a checkout, a link to skill-package/).
DEFAULT_MODEL = (
    Path(__file__).with_name("skill-package") / "interactionModels" / "custom" / "en-US.json"
)
FALLBACK = "AMAZON.FallbackIntent"
# The phrases Alexa's built-in intents answer to (a representative subset).
BUILTIN_SAMPLES = {
    "AMAZON.HelpIntent": ["help", "help me", "what can i say", "what can i do", "what can you do"],
    "AMAZON.StopIntent": ["stop", "off", "shut up", "be quiet", "that's all", "never mind"],
    "AMAZON.CancelIntent": ["cancel", "cancel that", "forget it", "nothing"],
    "AMAZON.NavigateHomeIntent": ["go home", "go to the home screen"],
    "AMAZON.YesIntent": ["yes", "yeah", "sure", "yes please"],
    "AMAZON.NoIntent": ["no", "no thanks", "nope"],
}
_WORD = re.compile(r"[^a-z0-9' ]+")
_SLOT_REF = re.compile(r"\{([A-Za-z0-9_.]+)\}")


def normalize(text: str) -> str:
    """Lower case, punctuation dropped (apostrophes kept), single spaces."""
    return " ".join(_WORD.sub(" ", text.lower().replace("-", " ")).split())


@dataclass(frozen=True)
class SlotValue:
    """A filled slot: what was said and, when it resolved, the value's id and name."""

    name: str
    type: str
    spoken: str
    id: str | None = None
    canonical: str | None = None

    @property
    def resolved(self) -> bool:
        return self.id is not None


@dataclass(frozen=True)
class Understanding:
    intent: str
    slots: dict[str, SlotValue] = field(default_factory=dict)
    # The names of every slot the intent declares, filled or not.
    declared: tuple[str, ...] = ()
    sample: str | None = None


@dataclass(frozen=True)
class _Pattern:
    intent: str
    sample: str
    regex: re.Pattern[str]
    slots: tuple[str, ...]
    literal_words: int


@dataclass(frozen=True)
class _SlotType:
    name: str
    # normalized phrase -> (id, canonical name)
    phrases: dict[str, tuple[str, str]]


class InteractionModel:
    """An `interactionModels/custom/<locale>.json`, ready to understand utterances."""

    def __init__(self, document: dict[str, Any]) -> None:
        try:
            language = document["interactionModel"]["languageModel"]
            self.invocation_name: str = language["invocationName"]
            intents = language["intents"]
        except (KeyError, TypeError) as err:
            raise VahrError(f"the interaction model lacks {err}") from err
        self.slot_types: dict[str, _SlotType] = {}
        for slot_type in language.get("types", []):
            phrases: dict[str, tuple[str, str]] = {}
            for value in slot_type.get("values", []):
                name = value["name"]["value"]
                value_id = value.get("id") or name
                for phrase in [name, *value["name"].get("synonyms", [])]:
                    phrases.setdefault(normalize(phrase), (value_id, name))
            self.slot_types[slot_type["name"]] = _SlotType(slot_type["name"], phrases)
        self.intent_slots: dict[str, dict[str, str]] = {}
        self._patterns: list[_Pattern] = []
        for intent in intents:
            name = intent["name"]
            slots = {slot["name"]: slot["type"] for slot in intent.get("slots", [])}
            self.intent_slots[name] = slots
            samples = intent.get("samples") or BUILTIN_SAMPLES.get(name, [])
            for sample in samples:
                self._patterns.append(_compile(name, sample))

    @classmethod
    def load(cls, path: Path | None = None) -> InteractionModel:
        file = path or DEFAULT_MODEL
        try:
            return cls(json.loads(Path(file).read_text()))
        except OSError as err:
            raise VahrError(f"cannot read the interaction model {file}: {err.strerror}") from err
        except ValueError as err:
            raise VahrError(f"the interaction model {file} is not valid JSON: {err}") from err

    def resolve(self, slot_type: str, spoken: str) -> tuple[str, str] | None:
        """(id, canonical name) of the slot type's value matching `spoken`, if any."""
        known = self.slot_types.get(slot_type)
        return known.phrases.get(normalize(spoken)) if known else None

    def slot_value(self, intent: str, slot: str, spoken: str) -> SlotValue:
        slot_type = self.intent_slots.get(intent, {}).get(slot, "")
        match = self.resolve(slot_type, spoken)
        return SlotValue(
            name=slot,
            type=slot_type,
            spoken=spoken,
            id=match[0] if match else None,
            canonical=match[1] if match else None,
        )

    def understand(self, utterance: str) -> Understanding:
        """The intent and slots Alexa would hear in `utterance` (inside the skill)."""
        text = normalize(utterance)
        best: tuple[tuple[int, int, int], Understanding] | None = None
        for pattern in self._patterns:
            found = pattern.regex.fullmatch(text)
            if found is None:
                continue
            slots = {
                slot: self.slot_value(pattern.intent, slot, found[f"s{index}"])
                for index, slot in enumerate(pattern.slots)
            }
            resolved = sum(1 for value in slots.values() if value.resolved)
            score = (int(resolved == len(slots)), pattern.literal_words, resolved)
            if best is None or score > best[0]:
                declared = tuple(self.intent_slots.get(pattern.intent, {}))
                best = (score, Understanding(pattern.intent, slots, declared, pattern.sample))
        if best is None:
            return Understanding(FALLBACK)
        return best[1]


def _compile(intent: str, sample: str) -> _Pattern:
    parts: list[str] = []
    slots: list[str] = []
    literal = 0
    position = 0
    for found in _SLOT_REF.finditer(sample):
        words = normalize(sample[position : found.start()])
        if words:
            parts.append(r"\s*".join(re.escape(word) for word in words.split()))
            literal += len(words.split())
        parts.append(f"(?P<s{len(slots)}>.+?)")
        slots.append(found[1])
        position = found.end()
    tail = normalize(sample[position:])
    if tail:
        parts.append(r"\s*".join(re.escape(word) for word in tail.split()))
        literal += len(tail.split())
    regex = re.compile(r"\s*".join(parts).replace(r"\s*\s*", r"\s*"))
    return _Pattern(intent, sample, regex, tuple(slots), literal)
