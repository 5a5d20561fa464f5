"""Whether the intent the classifier chose agrees with the slot values found in the words.

The classifier weighs words; the slot finder counts names. When the two tell different
stories the utterance is not understood, and the simulator falls back rather than act on
the classifier's side of it (a wrong action is worse than a question):

- an intent that takes no slot (the weather question, help, stop, cancel) is not what a
  person meant who named a robot or a zone ("hold it, robot one, don't move" is no cancel);
- an intent with slots is chosen only for as many values of each of its types as its own
  sample utterances hold together: no sequential-delivery sample names one robot and one
  zone, so "go to zone b with robot two" is not a sequential delivery, whatever its words.
  A type's count is capped at the intent's slots of that type, since extra values are
  the roles tagger's to sort out ("robot one and robot two" for one robot slot is the fleet).
"""

from __future__ import annotations

from collections import Counter
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping

    from vahr.assistant.slot_finder import SlotMatch

# How many values of each of an intent's slot types an utterance names, in the order of the
# intent's types: (1, 1) for "send robot one to zone b" read as a navigation.
Signature = tuple[int, ...]


class SlotConsistency:
    """The value counts each intent's samples show, and the check against them."""

    def __init__(
        self,
        intent_slots: Mapping[str, Mapping[str, str]],
        samples: Iterable[tuple[str, str]],
    ) -> None:
        """`intent_slots` are intent -> slot name -> type; `samples` are (intent, sample
        text with `{slot}` references)."""
        self._types = {
            intent: tuple(sorted(Counter(slots.values()).items()))
            for intent, slots in intent_slots.items()
        }
        self._seen: dict[str, set[Signature]] = {}
        for intent, sample in samples:
            slots = intent_slots.get(intent, {})
            named = Counter(
                slots[word[1:-1]]
                for word in sample.split()
                if word.startswith("{") and word[1:-1] in slots
            )
            self._seen.setdefault(intent, set()).add(self._signature(intent, named))

    def _signature(self, intent: str, named: Mapping[str, int]) -> Signature:
        types = self._types[intent]
        return tuple(min(named.get(slot_type, 0), slots) for slot_type, slots in types)

    def agrees(self, intent: str, matches: list[SlotMatch]) -> bool:
        """Whether `intent` fits the values found: none named for an intent without slots,
        and for one with slots, counts its samples show together."""
        if intent not in self._types:
            return True
        if not self._types[intent]:
            return not matches
        seen = self._seen.get(intent)
        if not seen:
            return True
        return self._signature(intent, Counter(match.type for match in matches)) in seen
