"""The one catch-all exception handler: log the failure, speak a safe sentence.

It maps the skill's error hierarchy (`skill.errors`) to speech in one place."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractExceptionHandler

from skill import prompts
from skill.errors import GatewayError
from skill.logs import get_logger, log_event
from skill.responses import in_conversation

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response


def speech_for(exception: Exception) -> str:
    """The sentence for a failure: the one place errors are mapped to speech."""
    if isinstance(exception, GatewayError):
        return prompts.GATEWAY_ERROR
    return prompts.GENERIC_ERROR


class CatchAllExceptionHandler(AbstractExceptionHandler):
    """Any exception a handler raises (or no handler at all) ends in valid speech."""

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
        speech = speech_for(exception)
        builder = handler_input.response_builder.speak(speech)
        if in_conversation(handler_input):
            return builder.ask(prompts.ERROR_REPROMPT).response
        return builder.set_should_end_session(True).response
