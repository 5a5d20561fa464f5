"""The announcer's errors: one family, each message one line a person can act on."""

from __future__ import annotations


class AnnouncerError(Exception):
    """Something stopped an announcement; the event is retried, then dead-lettered."""


class ConfigError(AnnouncerError):
    """The function's environment is wrong (a deployment mistake)."""


class DeliveryFailed(AnnouncerError):
    """Alexa did not accept an announcement; `retryable` says whether trying later helps."""

    def __init__(self, message: str, *, status: int | None = None, retryable: bool = True) -> None:
        super().__init__(message)
        self.status = status
        self.retryable = retryable


class StateConflict(AnnouncerError):
    """Another invocation changed the policy's state meanwhile; read it again."""
