"""The assistant's expected weather answers, read from `weather_answers.yaml`.

The same file feeds the offline recognizer's language model (every sentence in it), the
local interpreter (the cues and the rules for what is no answer; the negations are
`vahr.domain.weather.NEGATIONS`) and the CDK Lex bot (the intents' sentences), so what the
robot can hear and what it understands never drift apart.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import yaml

from vahr.domain.text import normalize
from vahr.domain.weather import NEGATIONS, WEATHERS
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from robot_agent.voice.port import WeatherIntent

ANSWERS_FILE = Path(__file__).with_name("weather_answers.yaml")
INTENTS: tuple[WeatherIntent, ...] = WEATHERS
_WORD_LISTS = (
    "clause_breaks",
    "question_openers",
    "question_verbs",
    "question_subjects",
    "robot_talk",
    "weak_cues",
    "other_times",
)


@dataclass(frozen=True)
class Cues:
    """What decides: per intent, the words and phrases that say it (`said`), and those
    that say it only when denied (`denied`: "not a cloud" is sunny)."""

    said: dict[WeatherIntent, tuple[tuple[str, ...], ...]]
    denied: dict[WeatherIntent, tuple[tuple[str, ...], ...]]
    negations: frozenset[str]
    negation_reach: int
    clause_breaks: frozenset[str]
    question_openers: frozenset[str]
    robot_talk: frozenset[str]
    # Cues that decide only when the other weather has none.
    weak: frozenset[str] = frozenset()
    # Verbs that open a question only with a subject after them ("is it raining", but not
    # "is raining right now", an answer whose "it" was not heard).
    question_verbs: frozenset[str] = frozenset()
    question_subjects: frozenset[str] = frozenset()
    # Words that put the weather said in their clause at another time ("next tuesday").
    other_times: frozenset[str] = frozenset()
    # Phrases that undo the cue before them, in its clause ("the sun will not be out").
    undone_after: tuple[tuple[str, ...], ...] = ()

    def words(self) -> set[str]:
        phrases = [*self.said.values(), *self.denied.values()]
        found = {word for group in phrases for phrase in group for word in phrase}
        return found | set(self.negations)


@dataclass(frozen=True)
class WeatherAnswers:
    """Sample phrasings per intent and sentences that are no answer (normalized, in file
    order, without duplicates), and the cues the interpreter decides by."""

    phrases: dict[WeatherIntent, tuple[str, ...]]
    not_answers: tuple[str, ...] = ()
    cues: Cues | None = None

    def intent_of(self, phrase: str) -> WeatherIntent:
        """The intent whose samples include `phrase` exactly (after normalizing), or unknown."""
        wanted = normalize(phrase)
        for intent, samples in self.phrases.items():
            if wanted in samples:
                return intent
        return "unknown"

    def all_phrases(self) -> list[str]:
        return [phrase for samples in self.phrases.values() for phrase in samples]

    def corpus(self) -> list[str]:
        """Every sentence the recognizer's language model is built from: the answers, what
        is no answer, and each cue alone (so every cue is a word the robot can hear)."""
        cues = self.cues
        alone = (
            []
            if cues is None
            else [
                " ".join(phrase)
                for table in (cues.said, cues.denied)
                for phrases in table.values()
                for phrase in phrases
            ]
        )
        return [*self.all_phrases(), *self.not_answers, *alone]

    @classmethod
    def parse(cls, document: object, source: str = "weather answers") -> WeatherAnswers:
        if not isinstance(document, dict) or not isinstance(document.get("intents"), dict):
            raise SpeechError(f"{source}: expected a mapping `intents: {{sunny: [...], ...}}`")
        intents = document["intents"]
        unexpected = sorted(set(intents) - set(INTENTS))
        if unexpected:
            raise SpeechError(f"{source}: unknown intents {unexpected}; expected sunny and rainy")
        phrases: dict[WeatherIntent, tuple[str, ...]] = {}
        seen: dict[str, str] = {}
        for intent in INTENTS:
            samples = intents.get(intent)
            if not isinstance(samples, list) or not samples:
                raise SpeechError(f"{source}: intents.{intent} must be a non-empty list")
            kept: list[str] = []
            for sample in samples:
                phrase = normalize(str(sample))
                if not phrase:
                    raise SpeechError(f"{source}: intents.{intent} has an empty phrase")
                if seen.get(phrase, intent) != intent:
                    raise SpeechError(
                        f"{source}: {sample!r} is listed under both {seen[phrase]} and {intent}"
                    )
                if phrase not in kept:
                    kept.append(phrase)
                seen[phrase] = intent
            phrases[intent] = tuple(kept)
        not_answers = _sentences(document.get("not_answers", []), "not_answers", source)
        for sentence in not_answers:
            if sentence in seen:
                raise SpeechError(
                    f"{source}: {sentence!r} is under both intents.{seen[sentence]} and not_answers"
                )
        cues = _cues(document, source) if "cues" in document else None
        return cls(phrases, not_answers, cues)

    @classmethod
    def load(cls, path: Path = ANSWERS_FILE) -> WeatherAnswers:
        return cls.parse(read_yaml(path, "the weather answers"), str(path))


# libyaml's parser where PyYAML was built with it: the sense check's data (thousands of
# sentences) is read at every robot start, and the pure-Python parser takes most of it.
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def read_yaml(path: Path, what: str) -> object:
    """The YAML document at `path`, or one `SpeechError` line saying what went wrong."""
    try:
        return yaml.load(path.read_text(encoding="utf-8"), Loader=_LOADER)
    except OSError as err:
        raise SpeechError(f"{path}: cannot read {what}: {err.strerror}") from err
    except yaml.YAMLError as err:
        raise SpeechError(f"{path}: not valid YAML: {err}") from err


def _sentences(value: object, key: str, source: str) -> tuple[str, ...]:
    if not isinstance(value, list):
        raise SpeechError(f"{source}: {key} must be a list of sentences")
    kept = [normalize(str(item)) for item in value]
    if not all(kept):
        raise SpeechError(f"{source}: {key} has an empty sentence")
    return tuple(dict.fromkeys(kept))


def _phrase_lists(value: object, key: str, source: str) -> dict[WeatherIntent, Any]:
    if not isinstance(value, dict) or sorted(set(value) - set(INTENTS)):
        raise SpeechError(f"{source}: {key} must map sunny and/or rainy to lists of words")
    found: dict[WeatherIntent, tuple[tuple[str, ...], ...]] = {}
    for intent, phrases in value.items():
        found[intent] = tuple(
            tuple(p.split()) for p in _sentences(phrases, f"{key}.{intent}", source)
        )
    return found


def _cues(document: dict[str, Any], source: str) -> Cues:
    cues = document["cues"]
    if not isinstance(cues, dict):
        raise SpeechError(f"{source}: cues must be a mapping of sunny, rainy and denied")
    denied = cues.get("denied", {})
    said = _phrase_lists({k: v for k, v in cues.items() if k != "denied"}, "cues", source)
    if "negations" in document:
        raise SpeechError(f"{source}: negations are vahr.domain.weather.NEGATIONS, not listed here")
    lists = {key: frozenset(_sentences(document.get(key, []), key, source)) for key in _WORD_LISTS}
    reach = document.get("negation_reach", 3)
    if not isinstance(reach, int) or not 1 <= reach <= 8:
        raise SpeechError(f"{source}: negation_reach must be a whole number of words, 1 to 8")
    return Cues(
        said=said,
        denied=_phrase_lists(denied, "cues.denied", source),
        negations=frozenset(NEGATIONS),
        negation_reach=reach,
        clause_breaks=lists["clause_breaks"],
        question_openers=lists["question_openers"],
        robot_talk=lists["robot_talk"],
        weak=lists["weak_cues"],
        question_verbs=lists["question_verbs"],
        question_subjects=lists["question_subjects"],
        other_times=lists["other_times"],
        undone_after=tuple(
            tuple(p.split())
            for p in _sentences(document.get("undone_after", []), "undone_after", source)
        ),
    )


def as_intent(value: str) -> WeatherIntent:
    return cast("WeatherIntent", value) if value in INTENTS else "unknown"
