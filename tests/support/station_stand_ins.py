"""Stand-ins around the station's API for tests that exercise it without a stack: the wire
its panel and desk publish to, recorded, and an assistant that records what it is asked."""

from __future__ import annotations

from typing import Any


class Wire:
    """Records every (topic, payload) the station publishes."""

    def __init__(self) -> None:
        self.sent: list[tuple[str, bytes]] = []

    def publish(self, topic: str, payload: bytes) -> None:
        self.sent.append((topic, payload))


class RecordingAssistant:
    """Answers every request with the weather and records (utterance, origin)."""

    def __init__(self) -> None:
        self.asked: list[tuple[str, str]] = []

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> dict[str, Any]:
        self.asked.append((utterance, origin))
        return {"speech": "It is sunny.", "intent": "WeatherIntent", "commands": []}
