"""The one catch-all exception handler: log the failure, speak a safe sentence.

It maps the skill's error hierarchy (`skill.errors`) to speech in one place."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractExceptionHandler

from skill import prompts
from skill.errors import GatewayError, PeopleUnavailable
from skill.guard import record_failure
from skill.logs import get_logger, log_event
from skill.responses import in_conversation

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime


def speech_for(exception: Exception) -> str:
    """The sentence for a failure: the one place errors are mapped to speech."""
    if isinstance(exception, PeopleUnavailable):
        return prompts.PEOPLE_UNAVAILABLE
    if isinstance(exception, GatewayError):
        return prompts.GATEWAY_ERROR
    return prompts.GENERIC_ERROR


class CatchAllExceptionHandler(AbstractExceptionHandler):
    """Any exception a handler raises (or no handler at all) ends in valid speech, and the
    request's record in the trail says it failed."""

    def __init__(self, runtime: SkillRuntime | None = None) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput, exception: Exception) -> bool:
        return True

    def handle(self, handler_input: HandlerInput, exception: Exception) -> Response:
        log_event(
            "failed",
            logging.ERROR,
            error_type=type(exception).__name__,
            error=str(exception),
        )
        get_logger().debug("traceback", exc_info=exception)
        if self.runtime is not None:
            try:
                record_failure(
                    handler_input, self.runtime, f"{type(exception).__name__}: {exception}"
                )
            except Exception as failure:  # the answer matters more than its record
                log_event(
                    "trail_failed",
                    logging.ERROR,
                    error_type=type(failure).__name__,
                    error=str(failure),
                )
        speech = speech_for(exception)
        builder = handler_input.response_builder.speak(speech)
        if in_conversation(handler_input):
            return builder.ask(prompts.ERROR_REPROMPT).response
        return builder.set_should_end_session(True).response
