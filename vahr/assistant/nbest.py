"""How sure a hearing is of what moves a robot: the recognizer's N best, each understood
by the NLU, weighed into one understanding with a confidence per slot value (the
operator station's push-to-talk uses it).

Each distinct transcript i of the N best gets a posterior from its path score,
`w_i ∝ exp(SHARPNESS * (score_i - score_best))` (a softmax whose one constant, how many
decoder log units make a factor e, is fitted on the tuning voices by the likelihood of
the right zone and robot: temperature scaling). Each transcript is understood by the NLU,
whose calibrated intent probability c_i splits w_i between its intent (w_i * c_i) and
the fallback. Then:

- the intent is the one with the most weight; below `MIN_INTENT_CONFIDENCE` of the whole,
  or the fallback, nothing is acted on;
- nothing is weighed when the best transcript holds a word the lattice gives less than
  `MIN_WORD_POSTERIOR` (speech about something else, heard as the model's words);
- each robot or zone slot of the leading reading gets P(value) = the weight of the
  readings of that intent giving the slot that value, over all readings of that intent. A
  value below `MIN_SLOT_CONFIDENCE` is not acted on: with rival values heard, the slot
  carries them as alternatives and the skill asks ("Zone B or zone D?"); with none (the
  other readings lack the slot) the slot is left empty and the skill asks for it.

The four constants are chosen on the tuning voices only (`bench/station_hearing.py`,
docs/push-to-talk.md).

A second recognizer that errs differently (Whisper, beside pocketsphinx) is used by
`agreement`: a request both transcripts read alike is acted on without weighing; and by
`stop_heard`: a stop either ear hears clearly is acted on, as stopping is always safe.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from vahr.assistant.nlu import CONFIDENCE_THRESHOLD, SlotValue, Understanding
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.skill_model.intents import EMERGENCY_STOP, ROBOT_TYPE, ZONE_TYPE
from vahr.speech.stt import Hypothesis

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from vahr.assistant.nlu import InteractionModel
    from vahr.speech.stt import Recognition

# Decoder log units (base 1.0001) per factor e between two transcripts' posteriors.
# Fitted on the tuning voices (bench/station_hearing.py): of 1/25 to 1/1600, the sharpness
# that gives the labelled zone and robot the highest likelihood (mean negative
# log-likelihood 1.046; 1.352 at 1/25, 1.066 at 1/1600).
SHARPNESS = 1 / 200
# The three thresholds below were chosen together on the tuning voices by one rule: the
# most requests right less ten times the wrong actions (out-of-domain sentences acted on
# count as wrong actions: a robot sent where nobody asked costs far more than a question),
# ties to the lowest. The tuning voices are heard poorly, so the rule chose the highest
# thresholds of the grid: push-to-talk acts rarely and wrongly more rarely still
# (docs/push-to-talk.md).
MIN_SLOT_CONFIDENCE = 0.9
MIN_INTENT_CONFIDENCE = 0.9
# The least lattice posterior of a word of the best transcript (`Recognition.confidence`)
# for anything to be weighed at all: speech about something else comes out as the model's
# words, each barely supported by the audio, which an NLU may still read as a request.
# Chosen with the two above; 0.3 until the NLU learnt "the robot" requests and the roles'
# confidence (the rule then chose 0.2 over 0.3, the other two unchanged).
MIN_WORD_POSTERIOR = 0.2
# The request that halts robots: acted on when either ear hears it clearly (`stop_heard`).
STOP_INTENT = EMERGENCY_STOP.name
# Slot types whose value moves a robot somewhere: never acted on when unsure.
MOVING_TYPES = frozenset({ROBOT_TYPE, ZONE_TYPE})
# A rival value is offered in the question only when it holds this share of the weight.
MIN_RIVAL_SHARE = 0.1


@dataclass(frozen=True)
class Weighed:
    """The understanding to act on, and how sure of it the hearing is."""

    understanding: Understanding
    intent_confidence: float
    # Slot name -> P(the value acted on or asked about), for the robot and zone slots.
    slot_confidence: dict[str, float]
    readings: int
    # Heard alike by two recognizers (`agreement`) rather than weighed from the N best.
    agreed: bool = False
    # The words the understanding was read from, when not the first ear's best transcript
    # (a stop only the second ear heard clearly, `stop_heard`).
    words: str | None = None

    def to_json(self) -> dict[str, object]:
        return {
            "intent": self.understanding.intent,
            "intent_confidence": round(self.intent_confidence, 3),
            "slots": {name: round(p, 3) for name, p in self.slot_confidence.items()},
            "readings": self.readings,
            "agreed": self.agreed,
            **({"words": self.words} if self.words is not None else {}),
        }


@dataclass(frozen=True)
class Weighing:
    """The constants of the combination (defaults: those chosen on the tuning voices)."""

    sharpness: float = SHARPNESS
    min_slot_confidence: float = MIN_SLOT_CONFIDENCE
    min_intent_confidence: float = MIN_INTENT_CONFIDENCE
    min_word_posterior: float = MIN_WORD_POSTERIOR


def posteriors(hypotheses: Sequence[Hypothesis], sharpness: float) -> list[float]:
    """Each hypothesis's share of the weight: a softmax of its score times `sharpness`."""
    if not hypotheses:
        return []
    top = max(h.score for h in hypotheses)
    raw = [math.exp(sharpness * (h.score - top)) for h in hypotheses]
    total = sum(raw)
    return [r / total for r in raw]


def weigh(
    hypotheses: Sequence[Hypothesis],
    understand: Callable[[str], Understanding],
    weighing: Weighing = Weighing(),
) -> Weighed:
    """The understanding push-to-talk acts on, from the N best (best first)."""
    if not hypotheses:
        return Weighed(Understanding(FALLBACK_INTENT, confidence=1.0), 1.0, {}, 0)
    weights = posteriors(hypotheses, weighing.sharpness)
    readings = [understand(h.text) for h in hypotheses]
    mass: dict[str, float] = defaultdict(float)
    for weight, reading in zip(weights, readings, strict=True):
        share = reading.confidence if reading.intent != FALLBACK_INTENT else 1.0
        mass[reading.intent] += weight * share
        mass[FALLBACK_INTENT] += weight * (1.0 - share)
    intent = max(mass, key=lambda name: (mass[name], name != FALLBACK_INTENT))
    intent_confidence = mass[intent]
    if intent == FALLBACK_INTENT or intent_confidence < weighing.min_intent_confidence:
        guess = intent if intent != FALLBACK_INTENT else None
        fallback = Understanding(FALLBACK_INTENT, confidence=intent_confidence, best_guess=guess)
        return Weighed(fallback, intent_confidence, {}, len(readings))
    agreeing = [
        (weight * reading.confidence, reading)
        for weight, reading in zip(weights, readings, strict=True)
        if reading.intent == intent
    ]
    lead = agreeing[0][1]  # the best-scored reading of that intent
    slots = dict(lead.slots)
    confidence: dict[str, float] = {}
    for name, value in lead.slots.items():
        if value.type not in MOVING_TYPES:
            continue
        shares, names = _value_shares(name, agreeing)
        confidence[name] = shares.get(value.id, 0.0)
        # A value the NLU already asks about stays a question, with its own rivals.
        if confidence[name] < weighing.min_slot_confidence and not value.alternatives:
            unsure = _unsure(value, shares, names)
            if unsure is None:
                del slots[name]  # asked for, as if it had not been said
            else:
                slots[name] = unsure
    return Weighed(replace(lead, slots=slots), intent_confidence, confidence, len(readings))


def weigh_recognition(
    model: InteractionModel,
    recognition: Recognition,
    weighing: Weighing = Weighing(),
    reading: Callable[[str], Understanding] | None = None,
) -> Weighed:
    """`weigh` over a recognition's N best (its transcript alone when it has none), each
    read by `reading` (the simulator's, in the dialog under way), else by `model` as the
    simulator reads a request (the invocation taken off)."""
    if not recognition.accepted or recognition.confidence < weighing.min_word_posterior:
        nothing = Understanding(FALLBACK_INTENT, confidence=1.0)
        return Weighed(nothing, 0.0, {}, 0)
    hypotheses = recognition.hypotheses or (Hypothesis(recognition.text, 0.0),)
    return weigh(hypotheses, reading or request_reader(model), weighing)


def agreement(
    model: InteractionModel,
    heard: str,
    confirming: str,
    reading: Callable[[str], Understanding] | None = None,
) -> Weighed | None:
    """The reading of `heard` to act on at once, when it is a request and a second,
    independent hearing of the same clip (`confirming`) reads as the same intent with the
    same robots and zones, each heard as one value; None otherwise (the N best are weighed
    instead). Each is read by `reading` (the simulator's, in the dialog under way), else as
    a request. Two recognizers that err differently rarely make the same mistake: on the
    development voices, of the requests both heard alike none moved a robot other than
    said (docs/decisions/0003-push-to-talk-two-ears.md)."""
    read = reading or request_reader(model)
    first, second = read(heard), read(confirming)
    if first.intent == FALLBACK_INTENT or _moving(model, first) != _moving(model, second):
        return None
    confidence = {name: 1.0 for name, _ in _moving(model, first)[1]}
    return Weighed(first, 1.0, confidence, 2, agreed=True)


def stop_heard(
    model: InteractionModel,
    heard: str,
    reading: Callable[[str], Understanding] | None = None,
) -> Weighed | None:
    """`heard` (one ear's transcript) read as a stop, when it clearly is one: the stop
    intent at the NLU's own confidence threshold, its robot (if named) heard as one value.
    A stop is the one request where acting is always safe, so a stop either ear hears
    clearly is acted on even when the other ear heard something else or nothing it
    understood (`bench/wrong_stops.py` measures what it costs and gains). None otherwise."""
    read = reading or request_reader(model)
    understood = read(heard)
    if understood.intent != STOP_INTENT or understood.confidence < CONFIDENCE_THRESHOLD:
        return None
    if any(value.alternatives or not value.resolved for value in understood.slots.values()):
        return None
    confidence = {name: 1.0 for name in understood.slots}
    return Weighed(understood, understood.confidence, confidence, 1, words=heard)


def disputed(
    model: InteractionModel, decided: Understanding, second: Understanding
) -> Understanding:
    """`decided` (weighed from the N best) with each robot or zone that a second hearing of
    the same clip, read as the same intent, heard as another value made a question between
    the two ("Zone B or zone D?"): two recognizers that disagree on a value are sure of
    neither. Nothing is asked when the second hearing is of another intent, since then it
    is the one more likely to have misheard the whole."""
    if decided.intent == FALLBACK_INTENT or second.intent != decided.intent:
        return decided
    types = model.intent_slots.get(decided.intent, {})
    slots = dict(decided.slots)
    for name, value in decided.slots.items():
        other = second.slots.get(name)
        if types.get(name) not in MOVING_TYPES or value.alternatives or other is None:
            continue
        if value.id is not None and other.id is not None and other.id != value.id:
            slots[name] = replace(value, alternatives=((other.id, other.canonical or other.id),))
    return replace(decided, slots=slots) if slots != decided.slots else decided


def request_reader(model: InteractionModel) -> Callable[[str], Understanding]:
    """Words read as the simulator reads a request (the invocation taken off), as the
    N best are read without a simulator's dialog."""
    from vahr.assistant.simulator import strip_invocation

    def understand(text: str) -> Understanding:
        return model.understand(strip_invocation(model.invocation_name, text))

    return understand


def _moving(
    model: InteractionModel, understanding: Understanding
) -> tuple[str, tuple[tuple[str, str | None], ...]]:
    """The intent and its robot and zone values (None for one asked about or unresolved):
    what two hearings must share to be acted on."""
    types = model.intent_slots.get(understanding.intent, {})
    values = (
        (name, None if value.alternatives else value.id)
        for name, value in understanding.slots.items()
        if types.get(name) in MOVING_TYPES
    )
    return understanding.intent, tuple(sorted(values))


def _value_shares(
    name: str, agreeing: list[tuple[float, Understanding]]
) -> tuple[dict[str | None, float], dict[str, str]]:
    """P(value id) of slot `name` among the readings of one intent (None: left empty),
    and each value's canonical name."""
    shares: dict[str | None, float] = defaultdict(float)
    names: dict[str, str] = {}
    total = sum(weight for weight, _ in agreeing)
    for weight, reading in agreeing:
        value = reading.slots.get(name)
        if value is None or value.id is None:
            shares[None] += weight
            continue
        names[value.id] = value.canonical or value.id
        names.update(value.alternatives)
        if value.alternatives:
            # A reading that already asks counts for none of its values.
            shares[None] += weight
        else:
            shares[value.id] += weight
    return ({key: share / total for key, share in shares.items()} if total else {}), names


def _unsure(
    value: SlotValue, shares: dict[str | None, float], names: dict[str, str]
) -> SlotValue | None:
    """`value` not to be acted on: with the rival values heard as alternatives (asked
    about), or None (the slot is asked for) when no rival value was heard. Not a value
    without its resolution: the skill would answer that it knows no zone called that."""
    rivals = tuple(
        (value_id, names.get(value_id, value_id))
        for value_id, share in sorted(shares.items(), key=lambda item: -item[1])
        if value_id is not None and value_id != value.id and share >= MIN_RIVAL_SHARE
    )
    return replace(value, alternatives=rivals) if rivals else None
