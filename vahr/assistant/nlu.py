"""Natural-language understanding built from the skill's interaction model, as Alexa does it.

Understanding an utterance takes three steps, each from the same generated model:

1. Slot values are found first (`slot_finder`): names of the ROBOT and ZONE values, with
   misheard words matched approximately, and unknown names ("robot nine") kept unresolved.
2. The intent is chosen by a classifier (`intent_classifier`) trained on the expanded sample
   utterances with the slots abstracted, plus the simulator's stand-ins for Alexa's own data
   (`background`: built-in intents and out-of-domain requests). Values of one type listed
   with a joiner of the language ("ROBOT and ROBOT") are read as one, in training and in
   use alike: a sample names each slot once, so no sample shows a list for one slot. Its
   confidence is calibrated; below `CONFIDENCE_THRESHOLD` the answer is
   AMAZON.FallbackIntent.
3. The intent is held to the values found (`consistency`): an intent that takes no slot is
   not chosen when a robot or zone was named, nor one whose samples never name as many
   values of its types together; either way the answer is the fallback.
4. The values found are given to the intent's slots by a tagger trained on the same samples
   with their slots labelled (`roles`); a type the intent takes that is named but given
   no slot is words that do not fit the intent, and the answer is the fallback. The
   tagger's posterior of its reading is `Understanding.roles_confidence`; below
   `ROLES_CONFIDENCE_THRESHOLD` the reading is confirmed before it is acted on.

What the NLU knows of the language beyond the model (the built-in intents' phrases, the
out-of-domain sentences, the function words around names, the role examples) is the
locale's `understanding.yaml` (`understanding`).

Slot values resolve as Alexa's entity resolution does (ER_SUCCESS_MATCH with the value's id
and name, or ER_SUCCESS_NO_MATCH). The trained classifier is cached on disk under a hash
of its training data, and can be built on a background thread so that `vahr up` does not
wait for it; the first utterance does.
"""

from __future__ import annotations

import copy
import json
import threading
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rapidfuzz import fuzz, process

from vahr.assistant import roles
from vahr.assistant.ambiguity import SlotAmbiguity
from vahr.assistant.background import built_in_phrases, out_of_domain_phrases
from vahr.assistant.consistency import SlotConsistency
from vahr.assistant.intent_classifier import MARKERS, load_or_train
from vahr.assistant.slot_finder import SlotFinder, SlotMatch, SlotTypeValues, normalize_utterance
from vahr.assistant.understanding import LanguageUnderstanding, load_understanding
from vahr.domain import FLEET_GROUP
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.errors import VahrError
from vahr.model_cache import default_cache_dir
from vahr.skill_model.intents import GROUP_TYPE, ROBOT_TYPE, ZONE_TYPE

if TYPE_CHECKING:
    from vahr.speech.text_classifier import TextClassifier

__all__ = [
    "CONFIDENCE_THRESHOLD",
    "ROLES_CONFIDENCE_THRESHOLD",
    "DEFAULT_MODEL",
    "FALLBACK_INTENT",
    "InteractionModel",
    "SlotValue",
    "Understanding",
    "normalize_utterance",
]

# The interaction model ships with the package (in a checkout, a link to skill-package/).
DEFAULT_MODEL = (
    Path(__file__).with_name("skill-package") / "interactionModels" / "custom" / "en-US.json"
)

# The classifier's label for a bare answer to "which robot?" ("robot one", "to zone b"),
# learnt from the slots' elicitation samples; it is never an intent of its own.
SLOT_ANSWER = "vahr.SlotAnswer"
# An intent is taken only when its calibrated probability reaches this; anything less is the
# fallback, as a wrong action is worse than asking. Set on the tuning set only, by the rule
# the hearing's thresholds follow (the most utterances right less three times the wrong
# ones, of 0.5, 0.55, 0.6, 0.65, 0.7 and 0.75); docs/history/nlu-tuning.md has the sweeps.
CONFIDENCE_THRESHOLD = 0.6
# A reading of which value fills which slot ("placebot one first, then placebot two") is
# acted on only when the roles tagger's posterior of it reaches this; below, the simulator
# asks the person to confirm the reading (`Understanding.needs_confirmation`). Chosen on the
# tuning set by the same rule, over 0.5 to 0.95 (docs/history/nlu-tuning.md).
ROLES_CONFIDENCE_THRESHOLD = 0.5
# An unknown place, robot or group is read as a slot's unresolved value (`_open_value`)
# when it is at most this many words the model has never seen, of these slot types.
OPEN_VALUE_MAX_WORDS = 3
# Robots are not: a robot the model does not know is read by its head word ("robot nine"),
# and "where is the kitchen" is a question about a place, not about a robot.
OPEN_TYPES = frozenset({ZONE_TYPE, GROUP_TYPE})
# ...and when the sentence around it is one of the intent's samples, word for word but for
# an article or so (`fuzz.ratio`): the classifier alone reads out-of-domain questions with
# an unknown word as requests ("what's the population of tokyo" as a status question). On
# the development set's out-of-domain sentences, 95 opens none; the skill's own sentences
# with an unknown place score 100.
OPEN_VALUE_LIKENESS = 90.0
# How long the first utterance may wait for a classifier still training in the background.
BUILD_TIMEOUT_S = 300.0


@dataclass(frozen=True)
class SlotValue:
    """A filled slot: what was said and, when it resolved, the value's id and name."""

    name: str
    type: str
    spoken: str
    id: str | None = None
    canonical: str | None = None
    # 100 for an exact name; lower when a misheard word was read as a name's word.
    similarity: float = 100.0
    # (id, canonical name) of the other values the words fit about as well (`ambiguity`):
    # the skill asks which was meant rather than act on this one.
    alternatives: tuple[tuple[str, str], ...] = ()

    @property
    def resolved(self) -> bool:
        return self.id is not None


@dataclass(frozen=True)
class Understanding:
    intent: str
    slots: dict[str, SlotValue] = field(default_factory=dict)
    # The names of every slot the intent declares, filled or not.
    declared: tuple[str, ...] = ()
    # The sample utterance closest to what was said (None for the fallback).
    sample: str | None = None
    # The calibrated probability of `intent` (of the best intent, for a fallback).
    confidence: float = 1.0
    # What the classifier would have chosen, when it fell short of the threshold.
    best_guess: str | None = None
    # The roles tagger's posterior of which value fills which slot (1.0 for an intent
    # with no slot roles to read, or values of one slot each), and the slots whose value's
    # role is below `ROLES_CONFIDENCE_THRESHOLD` on its own.
    roles_confidence: float = 1.0
    unsure_slots: tuple[str, ...] = ()

    @property
    def needs_confirmation(self) -> bool:
        """Whether the reading is too unsure to act on: the person is asked to confirm it
        first (the simulator's Dialog.ConfirmIntent), and a "no" sends nothing."""
        return self.intent != FALLBACK_INTENT and self.roles_confidence < ROLES_CONFIDENCE_THRESHOLD


class InteractionModel:
    """An `interactionModels/custom/<locale>.json`, ready to understand utterances.

    With `background=True` the classifier is loaded (or trained) on a thread; the first
    `understand` waits for it. `cache_dir=None` keeps nothing on disk.
    """

    def __init__(
        self,
        document: dict[str, Any],
        *,
        cache_dir: Path | None = None,
        background: bool = False,
        use_cache: bool = True,
        understanding: LanguageUnderstanding | None = None,
    ) -> None:
        """`understanding` is the locale's data beyond the model (en-US's by default)."""
        self._understanding = understanding or load_understanding()
        self._joiners = {
            normalize_utterance(word, self._understanding.locale)
            for word in self._understanding.finder.joiners
        }
        try:
            language = document["interactionModel"]["languageModel"]
            self.invocation_name: str = language["invocationName"]
            intents = language["intents"]
            locale = self._understanding.locale
            self._slot_types = [_slot_type(t, locale) for t in language.get("types", [])]
            self.intent_slots: dict[str, dict[str, str]] = {
                intent["name"]: {slot["name"]: slot["type"] for slot in intent.get("slots", [])}
                for intent in intents
            }
            samples = {intent["name"]: list(intent.get("samples", [])) for intent in intents}
            answers = {
                (intent["name"], answer)
                for intent in intents
                for slot in intent.get("slots", [])
                for answer in slot.get("samples", [])
            }
        except (KeyError, TypeError) as err:
            raise VahrError(f"the interaction model lacks {err}") from err
        self._samples: dict[str, list[tuple[str, str]]] = {}
        self.consistency = SlotConsistency(
            self.intent_slots,
            [(name, sample) for name, phrases in samples.items() for sample in phrases],
        )
        texts, labels = self._training_data(samples, sorted(answers))
        known = {word for text in texts for word in text.split()}
        self._type_names = {slot_type.name for slot_type in self._slot_types}
        # The words of the skill's own sentences (not of the out-of-domain stand-ins the
        # fallback learns from): a word outside them names nothing the skill knows.
        self._in_domain = {
            word
            for text, label in zip(texts, labels, strict=True)
            if label != FALLBACK_INTENT
            for word in text.split()
        }
        # The words that begin a value's name and are no value themselves ("the" of "the
        # pharmacy", "die" of "die ladezone"), by slot type: an unknown place said with
        # one ("the cafeteria") is read with it.
        self._leading_words = {
            slot_type.name: {name.split()[0] for name in slot_type.names if len(name.split()) > 1}
            - set(slot_type.names)
            for slot_type in self._slot_types
        }
        self._finder = SlotFinder(
            self._slot_types,
            [
                (sample, self.intent_slots[name])
                for name, phrases in samples.items()
                for sample in phrases
            ]
            + [(answer, self.intent_slots[name]) for name, answer in sorted(answers)],
            known,
            self._understanding.finder,
            self._understanding.locale,
        )
        self._ambiguity = SlotAmbiguity(self._slot_types, known)
        robot_values = [
            value for t in self._slot_types if t.name == ROBOT_TYPE for value in t.names.values()
        ]
        self._fleet = roles.Fleet(
            {v: name for v, name in robot_values if v != FLEET_GROUP},
            next((n for v, n in robot_values if v == FLEET_GROUP), "all robots"),
        )
        lexicon = roles.WeatherLexicon.of_locale(self._understanding.locale)
        # Labelled here, so that a role example naming what its intent lacks fails the load.
        role_values = {
            name: roles.training_values(
                name,
                slots,
                [self._normalized_sample(sample) for sample in samples[name]],
                self._understanding.roles,
            )
            for name, slots in self.intent_slots.items()
            if slots
        }
        self._taggers: dict[str, roles.RolesTagger] = {}
        # What each intent's roles tagger learns from, and the words it reads weather in.
        self._role_values = role_values
        self.role_lexicon = lexicon
        self.training = (texts, labels)
        self.cached: bool | None = None
        self._classifier: TextClassifier | None = None
        self._failure: BaseException | None = None
        self._ready = threading.Event()
        cache = (cache_dir or default_cache_dir()) if use_cache else None

        def build() -> None:
            try:
                for name, values in role_values.items():
                    self._taggers[name], _ = roles.load_or_learn(
                        name, self.intent_slots[name], values, cache, lexicon
                    )
                self._classifier, self.cached = load_or_train(texts, labels, cache)
            except BaseException as err:  # reported to whoever waits for the classifier
                self._failure = err
            finally:
                self._ready.set()

        if background:
            threading.Thread(target=build, name="vahr-nlu-build", daemon=True).start()
        else:
            build()

    def _training_data(
        self, samples: dict[str, list[str]], answers: list[tuple[str, str]]
    ) -> tuple[list[str], list[str]]:
        """The classifier's sentences and labels: the samples with slots abstracted, the
        built-in intents' phrases, the slots' answers, and the out-of-domain requests."""
        texts: list[str] = []
        labels: list[str] = []
        for name, phrases in samples.items():
            for sample in phrases:
                abstracted = self._abstract_sample(name, sample)
                self._samples.setdefault(name, []).append((abstracted, sample))
                texts.append(abstracted)
                labels.append(name)
        for name, phrases in built_in_phrases(understanding=self._understanding).items():
            if name in self.intent_slots:
                for phrase in phrases:
                    self._samples.setdefault(name, []).append((phrase, phrase))
                    texts.append(phrase)
                    labels.append(name)
        for name, answer in answers:
            texts.append(self._abstract_sample(name, answer))
            labels.append(SLOT_ANSWER)
        if FALLBACK_INTENT in self.intent_slots:
            background = out_of_domain_phrases(understanding=self._understanding)
            texts += background
            labels += [FALLBACK_INTENT] * len(background)
        return texts, labels

    @classmethod
    def load(cls, path: Path | None = None, **options: Any) -> InteractionModel:
        file = path or DEFAULT_MODEL
        try:
            document = json.loads(Path(file).read_text())
        except OSError as err:
            raise VahrError(f"cannot read the interaction model {file}: {err.strerror}") from err
        except ValueError as err:
            raise VahrError(f"the interaction model {file} is not valid JSON: {err}") from err
        return cls(document, **options)

    @cached_property
    def role_training(self) -> dict[str, list[roles.Sequence_]]:
        """What each intent's roles tagger learns from: its sentences' value features and
        labels (made when asked: a tagger from the cache needs none)."""
        return {
            name: roles.training_sequences(values, self.role_lexicon)
            for name, values in self._role_values.items()
        }

    @property
    def language(self) -> LanguageUnderstanding:
        """What the model knows of its language beyond the interaction model (not an
        `Understanding`, which is what it made of one utterance)."""
        return self._understanding

    def slot_value(self, intent: str, slot: str, value_id: str) -> SlotValue:
        """The slot `slot` of `intent` filled with the value `value_id`, said by its
        canonical name (as a labelled set means it); raises VahrError for an unknown one."""
        type_name = self.intent_slots.get(intent, {}).get(slot)
        for slot_type in self._slot_types:
            if slot_type.name != type_name:
                continue
            for found_id, canonical in slot_type.names.values():
                if found_id == value_id:
                    return SlotValue(slot, slot_type.name, canonical, found_id, canonical)
        raise VahrError(f"{intent} has no slot {slot} with a value {value_id!r}")

    @property
    def ready(self) -> bool:
        """Whether understanding can start without waiting: the classifier and the roles
        taggers are built (or building them failed, which `understand` then reports)."""
        return self._ready.is_set()

    def wait_ready(self, timeout_s: float = BUILD_TIMEOUT_S) -> TextClassifier:
        """The classifier, once built; raises VahrError if building failed or timed out."""
        if not self._ready.wait(timeout_s):
            raise VahrError(f"the intent classifier was not ready within {timeout_s:.0f} s")
        if self._classifier is None:
            raise VahrError(f"the intent classifier could not be built: {self._failure}")
        return self._classifier

    @property
    def taggers(self) -> dict[str, roles.RolesTagger]:
        """Each intent's roles tagger, once built."""
        self.wait_ready()
        return dict(self._taggers)

    def with_taggers(self, taggers: dict[str, roles.RolesTagger]) -> InteractionModel:
        """This model reading slot roles with `taggers` instead of its own (the same
        classifier and slot finder): a cross-validation retrains the taggers without the
        sentences it holds out."""
        self.wait_ready()
        clone = copy.copy(self)
        clone._taggers = {**self._taggers, **taggers}
        return clone

    def find_slots(self, utterance: str) -> tuple[list[str], list[SlotMatch]]:
        words = normalize_utterance(utterance, self._understanding.locale).split()
        return words, self._finder.find(words)

    def understand(self, utterance: str) -> Understanding:
        """The intent and slots Alexa would hear in `utterance` (inside the skill)."""
        classifier = self.wait_ready()
        words, matches = self.find_slots(utterance)
        if not words:
            return Understanding(FALLBACK_INTENT, confidence=1.0)
        abstracted = self._listed_as_one(_abstract(words, matches))
        # Outside a dialog there is no question to answer: the answer reading is set aside.
        intent, confidence = classifier.scores(abstracted).without(SLOT_ANSWER).best
        base = 0.0 if intent == FALLBACK_INTENT else confidence
        for opened in (
            self._open_values(words, matches, base)
            if self._open(intent, confidence, matches, words)
            else []
        ):
            open_matches, _, open_intent, _ = opened
            if self.consistency.agrees(open_intent, open_matches):
                if self._assign(open_intent, open_matches, words)[0] is not None:
                    matches, abstracted, intent, confidence = opened
                    break
        declared = self.intent_slots.get(intent, {})
        assigned: dict[str, SlotMatch] | None = {}
        reading = None
        if intent != FALLBACK_INTENT and confidence >= CONFIDENCE_THRESHOLD:
            assigned, reading = self._assign(intent, matches, words)
        if (
            intent == FALLBACK_INTENT
            or confidence < CONFIDENCE_THRESHOLD
            or not self.consistency.agrees(intent, matches)
            or assigned is None
        ):
            guess = None if intent == FALLBACK_INTENT else intent
            return Understanding(FALLBACK_INTENT, confidence=confidence, best_guess=guess)
        slots = {name: _slot_value(name, declared[name], m) for name, m in assigned.items()}
        slots = self._with_alternatives(slots, assigned, words, matches)
        return Understanding(
            intent,
            slots,
            tuple(declared),
            self.nearest_sample(intent, abstracted),
            confidence,
            roles_confidence=reading.confidence if reading else 1.0,
            unsure_slots=_unsure_slots(reading, declared) if reading else (),
        )

    def _open(
        self, intent: str, confidence: float, matches: list[SlotMatch], words: list[str]
    ) -> bool:
        """Whether to look for a value the model has no name for: not when the sentence is
        read as a request whose every zone slot is filled (a request read whole stays as
        read)."""
        if intent == FALLBACK_INTENT or confidence < CONFIDENCE_THRESHOLD:
            return True
        if not self.consistency.agrees(intent, matches):
            return True
        assigned, _ = self._assign(intent, matches, words)
        if assigned is None:
            return True
        zones = [
            name for name, kind in self.intent_slots.get(intent, {}).items() if kind == ZONE_TYPE
        ]
        return not all(name in assigned for name in zones)

    def _open_values(
        self, words: list[str], matches: list[SlotMatch], confidence: float
    ) -> list[tuple[list[SlotMatch], str, str, float]]:
        """A place, robot or group the model has no name for, read as Alexa reads a custom
        slot's value it cannot resolve: words the model has never seen ("the cafeteria",
        "the night shift"), where the sentence around them reads as a request with a slot of
        that type, become that slot's value, unresolved, so the skill says it knows no such
        place and which there are, instead of not understanding the request. Taken only
        when that reading is confident and more so than the reading without it
        (`confidence`). Each reading as the matches, the abstracted words, the intent and
        its confidence, the most confident first; the caller takes the first its slots fit."""
        classifier = self.wait_ready()
        taken = {i for match in matches for i in range(match.start, match.end)}
        runs: list[tuple[int, int]] = []
        for index, word in enumerate(words):
            if word in self._in_domain or index in taken:
                continue
            if runs and runs[-1][1] == index:
                runs[-1] = (runs[-1][0], index + 1)
            else:
                runs.append((index, index + 1))
        readings: list[tuple[list[SlotMatch], str, str, float]] = []
        for start, end in runs:
            if end - start > OPEN_VALUE_MAX_WORDS:
                continue
            for slot_type in self._slot_types:
                if slot_type.name not in OPEN_TYPES:
                    continue
                named = sum(1 for match in matches if match.type == slot_type.name)
                first = start
                if first > 0 and first - 1 not in taken:
                    if words[first - 1] in self._leading_words.get(slot_type.name, ()):
                        first -= 1
                value = SlotMatch(
                    slot_type.name, first, end, " ".join(words[first:end]), None, None, 0.0
                )
                merged = sorted([*matches, value], key=lambda match: match.start)
                abstracted = self._listed_as_one(_abstract(words, merged))
                intent, score = classifier.scores(abstracted).without(SLOT_ANSWER).best
                # Only a slot the sentence left empty: a request read whole stays as read.
                slots = list(self.intent_slots.get(intent, {}).values())
                fits = slots.count(slot_type.name) > named
                if (
                    intent != FALLBACK_INTENT
                    and fits
                    and score >= CONFIDENCE_THRESHOLD
                    and score > confidence
                    and self._sample_likeness(intent, abstracted) >= OPEN_VALUE_LIKENESS
                    # Words of a request around the values ("send ... to"), not values alone.
                    and not set(abstracted.split()) <= self._type_names
                ):
                    readings.append((merged, abstracted, intent, score))
        return sorted(readings, key=lambda reading: -reading[3])

    def _sample_likeness(self, intent: str, abstracted: str) -> float:
        """How alike `abstracted` is to the intent's closest sample (0 to 100, by
        characters: the words in their order)."""
        samples = [text for text, _ in self._samples.get(intent, [])]
        best = process.extractOne(abstracted, samples, scorer=fuzz.ratio) if samples else None
        return float(best[1]) if best else 0.0

    def _assign(
        self, intent: str, matches: list[SlotMatch], words: list[str]
    ) -> tuple[dict[str, SlotMatch] | None, roles.RolesReading | None]:
        """The values given to the intent's slots (None when the words do not fit it), and
        the tagger's reading they came from."""
        declared = self.intent_slots.get(intent, {})
        if intent not in self._taggers:
            return {}, None
        reading = self._taggers[intent].read(words, matches)
        return roles.assign(declared, matches, reading.labels, self._fleet), reading

    def _with_alternatives(
        self,
        slots: dict[str, SlotValue],
        found: dict[str, SlotMatch],
        words: list[str],
        matches: list[SlotMatch] | None = None,
    ) -> dict[str, SlotValue]:
        """`slots`, each resolved value given the other values its words fit as well; a
        value said as several ("zone b or zone d") is those values, the first with the
        others as its alternatives, so the skill asks which one is meant."""
        corrected, _ = self._finder.correct(words)
        out = dict(slots)
        for name, value in slots.items():
            said = _values_said(value, matches or [])
            if len(said) > 1:
                (first_id, first_name), *rest = said
                out[name] = replace(
                    value, id=first_id, canonical=first_name, alternatives=tuple(rest)
                )
                continue
            match = found.get(name)
            if match is None or not value.resolved or value.similarity >= 100.0:
                continue
            span = (match.start, match.end)
            others = self._ambiguity.alternatives(words, corrected, span, value.type, value.id)
            if others:
                out[name] = replace(value, alternatives=others)
        return out

    def answer(self, utterance: str, intent: str, slot: str) -> SlotValue | None:
        """`utterance` read as the answer to a question for `slot` of `intent` ("which
        robot?"), or None when it is rather a request of its own ("where are the robots")
        or names no value of the slot's type."""
        classifier = self.wait_ready()
        slot_type = self.intent_slots.get(intent, {}).get(slot, "")
        words, matches = self.find_slots(utterance)
        values = [match for match in matches if match.type == slot_type]
        if not values:
            return None
        best, confidence = classifier.scores(self._listed_as_one(_abstract(words, matches))).best
        request = best not in (SLOT_ANSWER, FALLBACK_INTENT, intent)
        if request and confidence >= CONFIDENCE_THRESHOLD:
            return None
        # Several values are read as the intent's tagger reads them in a request: "robot one
        # and robot two" listed is the fleet, "robot one or robot two" a choice to ask about.
        tagger = self._taggers.get(intent)
        labels = tagger.labels(words, values) if tagger else [""] * len(values)
        modes = [label[:1] if label[:1] in (roles.LISTED, roles.CHOICE) else "" for label in labels]
        match = roles.combine(values, modes, self._fleet)
        found = self._with_alternatives(
            {slot: _slot_value(slot, slot_type, match)}, {slot: match}, words, values
        )
        return found[slot]

    def nearest_sample(self, intent: str, abstracted: str) -> str | None:
        """The intent's sample utterance whose words are closest to `abstracted`."""
        samples = self._samples.get(intent) or []
        if not samples:
            return None
        best = process.extractOne(
            abstracted, [text for text, _ in samples], scorer=fuzz.token_sort_ratio
        )
        return samples[best[2]][1] if best else None

    @staticmethod
    def _normalized_sample(sample: str) -> str:
        """A sample's words as the NLU reads words, its `{slot}` references kept."""
        words = [w if w.startswith("{") else normalize_utterance(w) for w in sample.split()]
        return " ".join(word for word in words if word)

    def _abstract_sample(self, intent: str, sample: str) -> str:
        types = self.intent_slots.get(intent, {})
        words = [
            types.get(word[1:-1], word) if word.startswith("{") else normalize_utterance(word)
            for word in sample.split()
        ]
        return self._listed_as_one(" ".join(word for word in words if word))

    def _listed_as_one(self, abstracted: str) -> str:
        """`abstracted` with values of one type listed ("ROBOT and ROBOT") as one value, as
        the classifier reads them: a list of robots for one slot is one robot slot's words,
        which no sample can show (a sample names each slot once)."""
        out: list[str] = []
        for word in abstracted.split():
            if word in MARKERS and len(out) >= 2 and out[-1] in self._joiners and out[-2] == word:
                out.pop()
                continue
            out.append(word)
        return " ".join(out)


def _slot_type(document: dict[str, Any], locale: str) -> SlotTypeValues:
    names: dict[str, tuple[str, str]] = {}
    for value in document.get("values", []):
        name = value["name"]["value"]
        value_id = value.get("id") or name
        for phrase in [name, *value["name"].get("synonyms", [])]:
            names.setdefault(normalize_utterance(phrase, locale), (value_id, name))
    return SlotTypeValues(document["name"], names)


def _values_said(value: SlotValue, matches: list[SlotMatch]) -> list[tuple[str, str]]:
    """(id, name) of the values an unresolved slot value was said as, when the tagger read
    several names as one value ("zone b or zone d", spoken "zone b and zone d")."""
    if value.resolved:
        return []
    parts = value.spoken.split(" and ")
    said = {
        m.id: m.canonical or m.id
        for m in matches
        if m.type == value.type and m.id is not None and m.spoken in parts
    }
    return list(said.items())


def _unsure_slots(reading: roles.RolesReading, declared: dict[str, str]) -> tuple[str, ...]:
    """The declared slots named by a label whose marginal is below the roles threshold."""
    unsure: list[str] = []
    for label, marginal in zip(reading.labels, reading.marginals, strict=True):
        if marginal >= ROLES_CONFIDENCE_THRESHOLD:
            continue
        for slot in label.lstrip(roles.LISTED + roles.CHOICE).split(roles.BOTH):
            if slot in declared and slot not in unsure:
                unsure.append(slot)
    return tuple(unsure)


def _slot_value(name: str, slot_type: str, match: SlotMatch) -> SlotValue:
    return SlotValue(name, slot_type, match.spoken, match.id, match.canonical, match.similarity)


def _abstract(words: list[str], matches: list[SlotMatch]) -> str:
    """The words with each slot value replaced by its type: "send ROBOT to ZONE"."""
    out: list[str] = []
    index = 0
    for match in matches:
        out += words[index : match.start]
        out.append(match.type)
        index = match.end
    out += words[index:]
    return " ".join(out)
