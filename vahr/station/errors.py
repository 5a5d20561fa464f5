"""The one error a station request is refused with, raised by the routes (`app`) and by
push-to-talk (`voice`) and turned into a reply in one place (`StationApp`)."""

from __future__ import annotations


class RequestError(Exception):
    """A request the station refuses: `status` and a one-line reason."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.message = message
