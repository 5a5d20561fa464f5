"""The port through which the executor talks to the assistant by voice.

Adapters raise `vahr.speech.errors.SpeechError` when the voice path fails. The executor
owns the conversation (what to say, retry once on `unknown`, the events it
publishes); an adapter owns the audio: where speech goes and where the answer comes from
(a speaker and microphone next to an Echo, or the local stack's room channel).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol

# A weather word (`vahr.domain.weather`), or `unknown` when the answer was not understood.
WeatherIntent = Literal["sunny", "rainy", "unknown"]


@dataclass(frozen=True)
class Heard:
    """What the robot understood of the assistant's spoken answer: the text heard (empty
    when the audio was not trusted), the intent, a confidence (0..1), the phrases that
    decided it, and why it is `unknown` when it is."""

    text: str
    intent: WeatherIntent
    confidence: float
    evidence: tuple[str, ...] = ()
    reason: str = ""


class Voice(Protocol):
    async def say(self, text: str) -> None:
        """Speak `text` to the assistant; returns when it has been spoken."""

    async def listen(self, timeout_s: float) -> Heard:
        """Wait up to `timeout_s` for the assistant's answer and interpret it.

        Silence or speech outside the expected answers comes back as intent `unknown`.
        """
