"""The assistant's expected weather answers, read from `weather_answers.yaml`.

The same file feeds the offline recognizer's grammar, the local interpreter and the CDK
Lex bot, so what the robot can hear and what it understands never drift apart.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, cast

import yaml

from vahr.protocol.weather import WEATHERS
from vahr.speech.errors import SpeechError
from vahr.speech.text import normalize

if TYPE_CHECKING:
    from robot_agent.voice.port import WeatherIntent

ANSWERS_FILE = Path(__file__).with_name("weather_answers.yaml")
INTENTS: tuple[WeatherIntent, ...] = WEATHERS


@dataclass(frozen=True)
class WeatherAnswers:
    """Sample phrasings per intent (normalized, in file order, without duplicates)."""

    phrases: dict[WeatherIntent, tuple[str, ...]]

    def intent_of(self, phrase: str) -> WeatherIntent:
        """The intent whose samples include `phrase` exactly (after normalizing), or unknown."""
        wanted = normalize(phrase)
        for intent, samples in self.phrases.items():
            if wanted in samples:
                return intent
        return "unknown"

    def all_phrases(self) -> list[str]:
        return [phrase for samples in self.phrases.values() for phrase in samples]

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
        return cls(phrases)

    @classmethod
    def load(cls, path: Path = ANSWERS_FILE) -> WeatherAnswers:
        try:
            document = yaml.safe_load(path.read_text(encoding="utf-8"))
        except OSError as err:
            raise SpeechError(f"{path}: cannot read the weather answers: {err.strerror}") from err
        except yaml.YAMLError as err:
            raise SpeechError(f"{path}: not valid YAML: {err}") from err
        return cls.parse(document, str(path))


def as_intent(value: str) -> WeatherIntent:
    return cast("WeatherIntent", value) if value in INTENTS else "unknown"
