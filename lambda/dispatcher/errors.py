"""The dispatcher's errors: one family, each message one line a person can act on.

`app.lambda_handler` maps them to answers in one place: a bad request is answered (the
skill speaks it), anything else raises so Lambda retries a rule's event and then hands it
to the dead-letter queue.
"""

from __future__ import annotations


class DispatcherError(Exception):
    """Something stopped the dispatcher; the invocation fails."""


class ConfigError(DispatcherError):
    """The function's environment is wrong (a deployment mistake)."""


class BadRequest(DispatcherError):
    """The caller asked for something that cannot be done as asked; nothing was changed.
    `status` is the HTTP status the local data plane answers the same request with, and
    `error` the dispatcher's `DispatchError.code` when the order itself was refused."""

    def __init__(self, message: str, *, status: int = 400, error: str | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.error = error


class StoreError(DispatcherError):
    """The task table could not be read or written."""


class SearchError(DispatcherError):
    """IoT fleet indexing could not answer (not built yet, throttled, refused)."""


class PublishError(DispatcherError):
    """A command could not be published to a robot."""


class AnnounceError(DispatcherError):
    """A lost task could not be told to the announcer function."""
