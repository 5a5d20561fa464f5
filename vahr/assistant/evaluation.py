"""Scoring the simulator's understanding on a labelled set of utterances (`vahr nlu --eval`).

A set is a YAML file: `utterances`, each with its `text`, expected `intent` and expected
`slots` (slot name -> value id; a slot not listed is expected empty), and `out_of_domain`,
sentences the skill should not act on. Each utterance ends in one of four outcomes:

- right: the intent and every slot's id are the expected ones;
- wrong: an action other than what was said: another intent (AMAZON.FallbackIntent aside),
  or a slot resolved to another robot or zone than said (for an out-of-domain sentence, any
  custom intent);
- fallback: AMAZON.FallbackIntent (what an out-of-domain sentence should get);
- asks: the right intent with a slot missing, unresolved or heard as several values, so the
  skill asks for it (for an out-of-domain sentence, a built-in intent such as help); or any
  intent whose slot roles are too unsure to act on (`Understanding.needs_confirmation`),
  which the simulator asks the person to confirm before the skill hears of it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.assistant.nlu import Understanding
from vahr.assistant.simulator import strip_invocation
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.speech.scoring import OutcomeTally, read_labelled_set

if TYPE_CHECKING:
    from vahr.assistant.nlu import InteractionModel

DEVELOPMENT_SET = Path(__file__).resolve().parent / "data" / "devset-en-US.yaml"
OUTCOMES = ("right", "wrong", "fallback", "asks")
OUT_OF_DOMAIN = "(out of domain)"


class LabelledUtterance(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    text: str
    intent: str
    slots: dict[str, str] = {}


class LabelledSet(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    utterances: list[LabelledUtterance] = []
    out_of_domain: list[str] = []

    @classmethod
    def load(cls, path: Path) -> LabelledSet:
        return read_labelled_set(path, cls)

    def items(self) -> list[LabelledUtterance]:
        return [
            *self.utterances,
            *(LabelledUtterance(t, FALLBACK_INTENT) for t in self.out_of_domain),
        ]


@dataclass(frozen=True)
class Scored:
    item: LabelledUtterance
    outcome: str
    understood: Understanding

    @property
    def as_labelled(self) -> bool:
        """Right for a request; the fallback for an out-of-domain sentence."""
        return self.outcome == ("fallback" if self.item.intent == FALLBACK_INTENT else "right")

    def to_json(self) -> dict[str, Any]:
        return {
            "text": self.item.text,
            "expected": {"intent": self.item.intent, "slots": self.item.slots},
            "got": {
                "intent": self.understood.intent,
                "slots": {name: value.id for name, value in self.understood.slots.items()},
                "confidence": round(self.understood.confidence, 3),
                "roles_confidence": round(self.understood.roles_confidence, 3),
            },
            "outcome": self.outcome,
        }


@dataclass
class Report:
    """What `vahr nlu --eval` prints: tallies per expected intent, in-domain, out of domain."""

    per_intent: dict[str, OutcomeTally]
    in_domain: OutcomeTally
    out_of_domain: OutcomeTally
    scored: list[Scored]

    def to_json(self) -> dict[str, Any]:
        return {
            "in_domain": self.in_domain.to_json(),
            "out_of_domain": self.out_of_domain.to_json(),
            "per_intent": {name: tally.to_json() for name, tally in self.per_intent.items()},
            "mistakes": [s.to_json() for s in self.scored if not s.as_labelled],
        }

    def table(self) -> str:
        lines = [f"{'intent':<28} {'n':>4} {'right':>7} {'wrong':>7} {'fallback':>9} {'asks':>7}"]
        rows = [*self.per_intent.items(), ("in domain", self.in_domain)]
        rows.append((OUT_OF_DOMAIN, self.out_of_domain))
        for name, tally in rows:
            lines.append(
                f"{name:<28} {tally.total:>4} {tally.rate('right'):>7.1%} "
                f"{tally.rate('wrong'):>7.1%} {tally.rate('fallback'):>9.1%} "
                f"{tally.rate('asks'):>7.1%}"
            )
        return "\n".join(lines)


def outcome(model: InteractionModel, item: LabelledUtterance, got: Understanding) -> str:
    if got.intent == FALLBACK_INTENT:
        return "fallback"
    if got.needs_confirmation:
        return "asks"
    if item.intent == FALLBACK_INTENT:
        return "asks" if got.intent.startswith("AMAZON.") else "wrong"
    if got.intent != item.intent:
        return "wrong"
    # A value with alternatives is asked about ("Zone B or zone D?"), never acted on.
    said = {name: None if value.alternatives else value.id for name, value in got.slots.items()}
    declared = model.intent_slots.get(item.intent, {})
    if any(said.get(name) not in (None, item.slots.get(name)) for name in declared):
        return "wrong"
    if all(said.get(name) == item.slots.get(name) for name in declared):
        return "right"
    return "asks"


def labelled_understanding(model: InteractionModel, item: LabelledUtterance) -> Understanding:
    """What `item` means, as an understanding: its intent and slots, each value said by its
    canonical name (for the skill to be handed what the label means)."""
    slots = {name: model.slot_value(item.intent, name, value) for name, value in item.slots.items()}
    declared = tuple(model.intent_slots.get(item.intent, {}))
    return Understanding(item.intent, slots, declared)


def evaluate(model: InteractionModel, labelled: LabelledSet) -> Report:
    """Understand every utterance of `labelled` and tally the outcomes."""
    per_intent: dict[str, OutcomeTally] = {}
    in_domain, out_of_domain = OutcomeTally(OUTCOMES), OutcomeTally(OUTCOMES)
    scored = []
    for item in labelled.items():
        understood = model.understand(strip_invocation(model.invocation_name, item.text))
        result = outcome(model, item, understood)
        scored.append(Scored(item, result, understood))
        if item.intent == FALLBACK_INTENT:
            out_of_domain.counts[result] += 1
            continue
        per_intent.setdefault(item.intent, OutcomeTally(OUTCOMES)).counts[result] += 1
        in_domain.counts[result] += 1
    return Report(dict(sorted(per_intent.items())), in_domain, out_of_domain, scored)
