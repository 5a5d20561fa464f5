"""Structured log lines carrying the per-request correlation id.

The correlation id is the Alexa request id (a fresh one when a request has none). The
request interceptor sets it; every line logged while handling that request carries it, so a
command id in the robots' logs leads back to the utterance that caused it.
"""

from __future__ import annotations

import json
import logging
from contextvars import ContextVar

LOGGER_NAME = "skill"
correlation_id: ContextVar[str] = ContextVar("correlation_id", default="-")


def get_logger() -> logging.Logger:
    return logging.getLogger(LOGGER_NAME)


def configure(level: str) -> None:
    """Set the skill's log level; Lambda's runtime already installed a handler on the root."""
    logger = get_logger()
    logger.setLevel(level)
    if not logging.getLogger().handlers and not logger.handlers:
        logging.basicConfig(format="%(levelname)s %(name)s %(message)s")


def log_event(event: str, level: int = logging.INFO, **fields: object) -> None:
    """One JSON log line: the event name, the correlation id and the given fields."""
    logger = get_logger()
    if logger.isEnabledFor(level):
        line = {"event": event, "correlation_id": correlation_id.get(), **fields}
        logger.log(level, json.dumps(line, default=str, sort_keys=False))
