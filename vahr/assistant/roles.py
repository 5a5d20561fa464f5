"""Giving the slot values found in an utterance to the intent's slots: a tagger learnt from data.

The labelled templates are the training data for slot roles as they are for intents. For
each intent with slots, a linear-chain CRF (CRFsuite, through python-crfsuite) is trained
on the intent's sample utterances from the interaction model, where every `{slot}` is a
value labelled with its slot name, and on the locale's role examples (`understanding.yaml`,
`roles`), which add what samples never show: a value that takes no slot (`{-ZONE}`: "from
the loading zone"), one listed with the value before it for the same slot (`{+robot}`:
"robot one and robot two"), and one offered as a choice (`{?zone}`: "zone a or zone b").

The tagger's sequence is the values found, in order, not the words: each value's features
are its type, its rank among the values (of its type and of the other types), and the
words around it (the nearest four on each side, position by position, up to the next
value; and every word before and after it as a bag), with each word of a weather also read
as its weather (turned round by a negation just before it): the weather words and the
negations are the language's (`vahr.domain.locale`, its `language.yaml`), and a locale
without them gives no weather features.
The chain's transitions learn the order of the roles ("firstRobot firstZone secondRobot").
No language's words are in this module: a new language, or a new intent with two robots
or two zones, is data.

What the labels leave open is settled by what the values are, not by words (`assign`):
several values for one slot are one value only when listed and together the whole fleet
(or all the same value), and otherwise a value that does not resolve, so the skill asks;
"the other robot" of a fleet of two is the robot not named; the fleet in one of two robot
slots beside one robot is the fleet's other robot; two robot slots never hold one robot
(the second is asked for); and one value for two slots of its type fills both unless it
stands between the two values of the other type, where it is the first one's. A type the
intent takes, named but given no slot at all, means the words do not fit the intent.

Each intent's model is cached on disk under a hash of its training data, as the intent
classifier is (`vahr.speech.text_classifier`): the labelled values of its sentences, the
lexicon and this module's source, which makes the features from them (`load_or_learn`), so
that a model read from the cache costs no feature of the thousands of sentences.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, replace
from importlib.metadata import version
from typing import TYPE_CHECKING

import pycrfsuite

from vahr.domain import FLEET_GROUP
from vahr.domain.locale import LocaleError
from vahr.domain.weather import plain_negations, weather_words
from vahr.errors import VahrError
from vahr.model_cache import code_digest, content_key, write_atomically
from vahr.skill_model.intents import ROBOT_TYPE
from vahr.skill_model.templates import expand

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence
    from pathlib import Path

    from vahr.assistant.slot_finder import SlotMatch
    from vahr.assistant.understanding import RoleExamples

# What the cached models depend on besides their data; change it with the features or the
# training parameters, and every cache is invalidated.
RECIPE = "1: type, ranks, words 4 each side, bags, weather; lbfgs c1 0.1 c2 0.1 200 iterations"
# CRFsuite's L-BFGS with sklearn-crfsuite's tutorial settings (elastic net 0.1 and 0.1), and
# every transition possible so that an order never seen in training can still be decoded.
TRAINING_PARAMETERS = {
    "c1": 0.1,
    "c2": 0.1,
    "max_iterations": 200,
    "feature.possible_transitions": True,
}
# A value that takes no slot.
NO_SLOT = "-"
LISTED = "+"
CHOICE = "?"
WINDOW = 4
# Label sequences scored one by one at most (a sentence of six values of six labels each).
MAX_SEQUENCES = 50_000
_REFERENCE = re.compile(r"^\{([-+?]?)([A-Za-z_.&]+)(!?)\}$")
# Between slot names, a value that fills each of them ("{firstZone&secondZone}").
BOTH = "&"

# A value in the words: its type, where it starts and ends, and whether it is the fleet.
Span = tuple[str, int, int, bool]
Sequence_ = tuple[list[list[str]], list[str]]
# A sentence's words (each value as `<TYPE>`), its values and their labels.
Values = tuple[list[str], list[Span], list[str]]


@dataclass(frozen=True)
class WeatherLexicon:
    """One language's words for each weather and the negations that turn one into the other
    ("if it's not sunny"), as the tagger reads them."""

    weathers: Mapping[str, str]
    negations: frozenset[str]

    @classmethod
    def of_locale(cls, locale: str) -> WeatherLexicon:
        """The locale's weather words from its `language.yaml`; none for a locale without."""
        try:
            named = weather_words(locale)
            negations = plain_negations(locale)
        except LocaleError:
            return cls({}, frozenset())
        weathers = {word: weather for weather, words in named.items() for word in words}
        return cls(weathers, frozenset(negations))

    def weather_of(self, words: Sequence[str], at: int) -> str | None:
        """The weather `words[at]` names, turned round by a negation up to two words before."""
        weather = self.weathers.get(words[at])
        if weather is None:
            return None
        if self.negations & set(words[max(0, at - 2) : at]):
            others = {w for w in self.weathers.values() if w != weather}
            return others.pop() if len(others) == 1 else None
        return weather


def value_features(
    words: Sequence[str], spans: Sequence[Span], lexicon: WeatherLexicon
) -> list[list[str]]:
    """The features of each value in `spans` (left to right) of the normalized `words`."""
    classes = [lexicon.weather_of(words, at) for at in range(len(words))]
    types = sorted({span[0] for span in spans})
    found: list[list[str]] = []
    for index, (type_name, start, end, _) in enumerate(spans):
        same = [span for span in spans if span[0] == type_name]
        rank = same.index(spans[index])
        features = [
            f"t={type_name}{'!' if spans[index][3] else ''}",
            f"rank={min(rank, 2)}",
            f"of={min(len(same), 3)}",
            f"at={min(index, 3)}",
        ]
        if index == len(spans) - 1:
            features.append("last")
        for other in types:
            before = sum(1 for span in spans[:index] if span[0] == other)
            features.append(f"before:{other}={min(before, 2)}")
        previous_end = spans[index - 1][2] if index else 0
        next_start = spans[index + 1][1] if index + 1 < len(spans) else len(words)
        for distance in range(1, WINDOW + 1):
            at = start - distance
            if at < previous_end:
                edge = f"<{spans[index - 1][0]}>" if index else "<s>"
                features.append(f"L{distance}:{edge}")
                break
            features.append(f"L{distance}:{words[at]}")
        for distance in range(1, WINDOW + 1):
            at = end + distance - 1
            if at >= next_start:
                edge = f"<{spans[index + 1][0]}>" if index + 1 < len(spans) else "</s>"
                features.append(f"R{distance}:{edge}")
                break
            features.append(f"R{distance}:{words[at]}")
        # What introduces the values of the same type before and after this one ("robot two
        # delivers to zone d *after* robot one"), which the chain alone would see too late.
        for side, neighbour in (("p", rank - 1), ("n", rank + 1)):
            if 0 <= neighbour < len(same) and same[neighbour][1] > 0:
                features.append(f"{side}L1:{words[same[neighbour][1] - 1]}")
        features += [f"l:{word}" for word in words[previous_end:start]]
        features += [f"r:{word}" for word in words[end:next_start]]
        nearest_left = next((c for c in reversed(classes[previous_end:start]) if c), None)
        nearest_right = next((c for c in classes[end:next_start] if c), None)
        if nearest_left:
            features.append(f"near-left~{nearest_left}")
        if nearest_right:
            features.append(f"near-right~{nearest_right}")
        features += [f"l~{c}" for c in classes[previous_end:start] if c]
        features += [f"r~{c}" for c in classes[end:next_start] if c]
        found.append(features)
    return found


def labelled_sequence(
    sentence: str, slot_types: Mapping[str, str], lexicon: WeatherLexicon
) -> Sequence_ | None:
    """A sample or role example as (features, labels); None when it names no value
    (`labelled_values`)."""
    values = labelled_values(sentence, slot_types)
    if values is None:
        return None
    words, spans, labels = values
    return value_features(words, spans, lexicon), labels


def labelled_values(sentence: str, slot_types: Mapping[str, str]) -> Values | None:
    """A sample or role example's words, values and labels; None when it names no value.

    `{slot}` is a value for the slot; `{-TYPE}` a value of the type for no slot; `{+slot}`
    and `{?slot}` a value listed with, or offered instead of, the one before it; `{a&b}` a
    value for both slots. A reference to anything else is a `VahrError` naming it."""
    words: list[str] = []
    spans: list[Span] = []
    labels: list[str] = []
    for token in sentence.split():
        reference = _REFERENCE.match(token)
        if reference is None:
            words.append(token)
            continue
        mode, name, fleet = reference.groups()
        kinds = {slot_types.get(slot) for slot in name.split(BOTH)}
        if mode == NO_SLOT and name in slot_types.values():
            spans.append((name, len(words), len(words) + 1, bool(fleet)))
            labels.append(NO_SLOT)
        elif mode != NO_SLOT and len(kinds) == 1 and None not in kinds:
            spans.append((kinds.pop() or "", len(words), len(words) + 1, bool(fleet)))
            labels.append(mode + name)
        else:
            known = ", ".join([*slot_types, *sorted(set(slot_types.values()))])
            raise VahrError(f"{token} in {sentence!r} is no slot or type of its intent ({known})")
        words.append(f"<{spans[-1][0]}>")
    if not spans:
        return None
    return words, spans, labels


class RolesTagger:
    """One intent's CRF over the values of an utterance, and the slot assignment after it."""

    def __init__(
        self, intent: str, slot_types: Mapping[str, str], model: bytes, lexicon: WeatherLexicon
    ) -> None:
        self.intent = intent
        self.slot_types = dict(slot_types)
        self.lexicon = lexicon
        # CRFsuite reads the model in place: the bytes must live as long as the tagger.
        self._model = model
        self._tagger = pycrfsuite.Tagger()
        self._tagger.open_inmemory(self._model)
        # The labels a value of each type may take: its type's slots' (as learnt), or none.
        known = self._tagger.labels()
        self._allowed = {
            slot_type: [
                label
                for label in known
                if label == NO_SLOT
                or self.slot_types.get(label.lstrip("+?").split(BOTH)[0]) == slot_type
            ]
            for slot_type in set(self.slot_types.values())
        }

    def labels(self, words: Sequence[str], matches: Sequence[SlotMatch]) -> list[str]:
        """A label for each of `matches`: a slot name (marked "+" or "?"), or `NO_SLOT` for
        a value of a type the intent does not take or one the tagger gives no slot."""
        return self.read(words, matches).labels

    def read(self, words: Sequence[str], matches: Sequence[SlotMatch]) -> RolesReading:
        """The labels of `labels` with how sure the tagger is of them (`RolesReading`)."""
        taken = [match for match in matches if match.type in self._allowed]
        if not taken:
            return RolesReading([NO_SLOT] * len(matches), 1.0, [1.0] * len(matches))
        self._tagger.set(self.features(words, taken))
        best, confidence, marginals = self._best_sequence(
            [self._allowed[match.type] for match in taken]
        )
        by_match = {
            id(match): (label, marginal)
            for match, label, marginal in zip(taken, best, marginals, strict=True)
        }
        read = [by_match.get(id(match), (NO_SLOT, 1.0)) for match in matches]
        return RolesReading([label for label, _ in read], confidence, [m for _, m in read])

    def features(self, words: Sequence[str], matches: Sequence[SlotMatch]) -> list[list[str]]:
        """What the CRF reads of the values of `matches` whose type the intent takes."""
        taken = [match for match in matches if match.type in self._allowed]
        # Each value stands as one word of its type, as `{slot}` does in the samples.
        abstracted: list[str] = []
        spans: list[Span] = []
        index = 0
        for match in taken:
            abstracted += words[index : match.start]
            spans.append(
                (match.type, len(abstracted), len(abstracted) + 1, match.id == FLEET_GROUP)
            )
            abstracted.append(f"<{match.type}>")
            index = match.end
        abstracted += words[index:]
        return value_features(abstracted, spans, self.lexicon)

    def _best_sequence(self, allowed: list[list[str]]) -> tuple[list[str], float, list[float]]:
        """The most probable labels with each value's label one its type allows (a value of
        one type never takes another type's slot), their probability among the allowed
        sequences, and each label's marginal probability among them. The sequences are few
        (a sentence names two to four values), so each is scored; a longer one is decoded
        unconstrained, its probability then among all sequences."""
        if math.prod(len(labels) for labels in allowed) > MAX_SEQUENCES:
            best = list(self._tagger.tag())
            confidence = self._tagger.probability(best)
            marginals = [self._tagger.marginal(label, at) for at, label in enumerate(best)]
            return best, confidence, marginals
        scored = [
            (self._tagger.probability(list(labels)), labels)
            for labels in itertools.product(*allowed)
        ]
        # CRFsuite's probability is among every label sequence; what the tagger may choose
        # is among the allowed ones only, so that is what it is normalised over.
        total = sum(probability for probability, _ in scored)
        top, best_labels = max(scored, key=lambda pair: pair[0])
        if total <= 0.0:
            return list(best_labels), 0.0, [0.0] * len(best_labels)
        marginals = [
            sum(p for p, labels in scored if labels[at] == label) / total
            for at, label in enumerate(best_labels)
        ]
        return list(best_labels), top / total, marginals


@dataclass(frozen=True)
class RolesReading:
    """The tagger's labels for the values of an utterance, with how sure it is of them.

    `confidence` is the posterior probability of the whole label sequence among the
    sequences the values' types allow; `marginals` is, for each value, the probability of
    its label summed over those sequences (a value whose label the runner-up sequences
    share is sure even when the sequence is not)."""

    labels: list[str]
    confidence: float
    marginals: list[float]


def training_values(
    intent: str,
    slot_types: Mapping[str, str],
    samples: Sequence[str],
    examples: Sequence[RoleExamples],
) -> list[Values]:
    """The intent's samples and the locale's role examples for it, labelled; a role example
    naming what the intent lacks is a `VahrError` naming the intent."""
    sentences = list(samples)
    for group in examples:
        if intent in group.intents:
            sentences += [s for template in group.examples for s in expand(template)]
    try:
        found = [labelled_values(sentence, slot_types) for sentence in sentences]
    except VahrError as err:
        raise VahrError(f"role examples of {intent}: {err}") from err
    return [values for values in found if values is not None]


def training_sequences(values: Sequence[Values], lexicon: WeatherLexicon) -> list[Sequence_]:
    """What the tagger learns from: each sentence's value features and labels."""
    return [(value_features(words, spans, lexicon), labels) for words, spans, labels in values]


def load_or_learn(
    intent: str,
    slot_types: Mapping[str, str],
    values: Sequence[Values],
    cache_dir: Path | None,
    lexicon: WeatherLexicon,
) -> tuple[RolesTagger, bool]:
    """The intent's tagger learnt from `values` (`training_values`), from the cache (True) or
    trained now and cached (False). Kept under what the features are made from: reading
    them from thousands of sentences took about 0.3 s of CPU at every load."""
    learnt_from = [
        RECIPE, TRAINING_PARAMETERS, version("python-crfsuite"), code_digest(__name__),
        intent, slot_types, values, sorted(lexicon.weathers.items()), sorted(lexicon.negations),
    ]  # fmt: skip
    return _cached_or_trained(
        intent, slot_types, learnt_from, lambda: training_sequences(values, lexicon), cache_dir,
        lexicon,
    )  # fmt: skip


def load_or_train(
    intent: str,
    slot_types: Mapping[str, str],
    sequences: list[Sequence_],
    cache_dir: Path | None,
    lexicon: WeatherLexicon,
) -> tuple[RolesTagger, bool]:
    """The intent's tagger learnt from `sequences`, from the cache (True) or trained now and
    cached (False)."""
    learnt_from = [RECIPE, TRAINING_PARAMETERS, version("python-crfsuite"), intent, sequences]
    return _cached_or_trained(
        intent, slot_types, learnt_from, lambda: sequences, cache_dir, lexicon
    )


def _cached_or_trained(
    intent: str,
    slot_types: Mapping[str, str],
    learnt_from: object,
    sequences: Callable[[], list[Sequence_]],
    cache_dir: Path | None,
    lexicon: WeatherLexicon,
) -> tuple[RolesTagger, bool]:
    """The tagger kept under a hash of `learnt_from`, read (True), or trained on
    `sequences()` (made only then) and kept (False)."""
    key = content_key(learnt_from)
    file = cache_dir / f"roles-{intent}-{key[:24]}.crfsuite" if cache_dir else None
    if file is not None:
        try:
            return RolesTagger(intent, slot_types, file.read_bytes(), lexicon), True
        except OSError:
            pass
    model = _train(sequences())
    if file is not None:
        write_atomically(file, model)
    return RolesTagger(intent, slot_types, model, lexicon), False


def _train(sequences: list[Sequence_]) -> bytes:
    import tempfile
    from pathlib import Path

    trainer = pycrfsuite.Trainer(verbose=False)
    for features, labels in sequences:
        trainer.append(features, labels)
    trainer.set_params(TRAINING_PARAMETERS)
    with tempfile.TemporaryDirectory(prefix="vahr-roles-") as directory:
        file = Path(directory) / "model.crfsuite"
        trainer.train(str(file))
        return file.read_bytes()


@dataclass(frozen=True)
class Fleet:
    """The robots of the fleet (id -> name, without the fleet's own id) and its name."""

    robots: Mapping[str, str]
    name: str


def assign(
    declared: Mapping[str, str],
    matches: Sequence[SlotMatch],
    labels: Sequence[str],
    fleet: Fleet,
) -> dict[str, SlotMatch] | None:
    """Slot name -> value for the slots of `declared` (name -> type), from the tagger's
    labels; None when a type the intent takes is named but given no slot."""
    given: dict[str, list[tuple[SlotMatch, str]]] = {}
    for match, label in zip(matches, labels, strict=True):
        mode, slots = (label[0], label[1:]) if label[:1] in (LISTED, CHOICE) else ("", label)
        for slot in slots.split(BOTH):
            if slot in declared:
                given.setdefault(slot, []).append((match, mode if slot in given else ""))
    named_types = {match.type for match in matches}
    if any(t in named_types and t not in {declared[s] for s in given} for t in declared.values()):
        return None
    filled: dict[str, SlotMatch] = {}
    for slot, values in given.items():
        filled[slot] = combine([value for value, _ in values], [m for _, m in values], fleet)
        plain = [value for value, mode in values[1:] if not mode]
        siblings = [s for s, t in declared.items() if t == declared[slot] and s not in given]
        if plain and siblings and len(values) == 2:
            # Two values said alike for one slot, beside an empty one of the same type: the
            # first is the slot's, the second is heard for the other but not guessed.
            filled[slot] = values[0][0]
            filled[siblings[0]] = replace(plain[0], id=None, canonical=None)
    return _completed(declared, filled, fleet)


def combine(values: Sequence[SlotMatch], modes: Sequence[str], fleet: Fleet) -> SlotMatch:
    """One value standing for the values said for one slot (`modes`: "" for the first or
    one said apart, "+" listed with the one before, "?" offered as a choice)."""
    first = values[0]
    ids = {value.id for value in values}
    if len(values) == 1 or (len(ids) == 1 and first.id is not None):
        return first
    spoken = " and ".join(value.spoken for value in values)
    listed = all(mode == LISTED for mode in modes[1:])
    robots = set(fleet.robots)
    if first.type == ROBOT_TYPE and listed and ids in (robots, {*robots, FLEET_GROUP}):
        # Robots listed where one is expected are all of them only when they are the fleet.
        return replace(first, spoken=spoken, id=FLEET_GROUP, canonical=fleet.name)
    return replace(first, spoken=spoken, id=None, canonical=None)


def _completed(
    declared: Mapping[str, str], filled: dict[str, SlotMatch], fleet: Fleet
) -> dict[str, SlotMatch]:
    """What the values are settles what the labels leave open (see the module's notes)."""
    robot_slots = [slot for slot, t in declared.items() if t == ROBOT_TYPE]
    robots = [filled[slot] for slot in robot_slots if slot in filled]
    if len(fleet.robots) == 2:
        named = {r.id for r in robots if r.id in fleet.robots}
        for slot in robot_slots:
            value = filled.get(slot)
            if value is None or len(named) != 1:
                continue
            (other,) = fleet.robots.keys() - named
            if value.refers_to_other or (value.id == FLEET_GROUP and len(robots) == 2):
                filled[slot] = replace(value, id=other, canonical=fleet.robots[other])
    if len(robot_slots) == 2 and all(slot in filled for slot in robot_slots):
        first, second = (filled[slot] for slot in robot_slots)
        if first.id is not None and first.id == second.id:
            filled[robot_slots[1]] = replace(second, id=None, canonical=None)
    by_type: dict[str, list[str]] = {}
    for slot, slot_type in declared.items():
        by_type.setdefault(slot_type, []).append(slot)
    for slot_type, slots in by_type.items():
        said = [slot for slot in slots if slot in filled]
        others = [s for t, ss in by_type.items() if t != slot_type for s in ss]
        # Two robot slots are two robots; two zones may be one ("both to zone d").
        if slot_type == ROBOT_TYPE or len(slots) != 2 or len(said) != 1 or len(others) != 2:
            continue
        value = filled[said[0]]
        pair = [filled[slot] for slot in others if slot in filled]
        if len(pair) == 2:
            first, second = pair
            if first.start < value.start < second.start:
                # Between the two values of the other type in their order: the first's.
                continue
            if second.start < first.start < value.start:
                # After both, said in the other order ("two waits for one, then to d"):
                # the one the tagger gave it.
                continue
        filled.update(dict.fromkeys(slots, value))
    return filled
