"""The launch request, the built-in intents (Help, Cancel, Stop, NavigateHome, Fallback) and
SessionEndedRequest: one class each."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name, is_request_type

from skill import prompts
from skill.logs import log_event
from skill.responses import ask, end, start_conversation
from vahr.domain.invocation import FALLBACK_INTENT

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response, SessionEndedRequest

    from skill.runtime import SkillRuntime


class LaunchRequestHandler(AbstractRequestHandler):
    """ "Alexa, open robot fleet": greet and keep the conversation open."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_request_type("LaunchRequest")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        start_conversation(handler_input)
        reprompt = prompts.WELCOME_REPROMPT.format(**self.runtime.vocabulary.examples())
        return ask(handler_input, prompts.WELCOME, reprompt)


class HelpIntentHandler(AbstractRequestHandler):
    """AMAZON.HelpIntent: say what the skill can do, with the fleet's own names."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("AMAZON.HelpIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        start_conversation(handler_input)
        speech = prompts.HELP.format(**self.runtime.vocabulary.examples())
        return ask(handler_input, speech, prompts.HELP_REPROMPT)


class CancelIntentHandler(AbstractRequestHandler):
    """AMAZON.CancelIntent: end the session; robots keep their current tasks."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("AMAZON.CancelIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        return end(handler_input, prompts.GOODBYE_ROBOTS_KEEP_GOING)


class StopIntentHandler(AbstractRequestHandler):
    """AMAZON.StopIntent: end the session (the robots' emergency stop is its own intent)."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("AMAZON.StopIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        return end(handler_input, prompts.GOODBYE_ROBOTS_KEEP_GOING)


class NavigateHomeIntentHandler(AbstractRequestHandler):
    """AMAZON.NavigateHomeIntent: leave the skill."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("AMAZON.NavigateHomeIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        return end(handler_input, prompts.GOODBYE)


class FallbackIntentHandler(AbstractRequestHandler):
    """AMAZON.FallbackIntent: say what the skill understands and keep listening."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name(FALLBACK_INTENT)(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        speech = prompts.FALLBACK_SPEECH.format(**self.runtime.vocabulary.examples())
        return ask(handler_input, speech, prompts.FALLBACK_REPROMPT)


class SessionEndedRequestHandler(AbstractRequestHandler):
    """SessionEndedRequest: log why; Alexa accepts no speech here."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_request_type("SessionEndedRequest")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        request: SessionEndedRequest = handler_input.request_envelope.request  # type: ignore[assignment]
        error = request.error
        log_event(
            "session_ended",
            reason=request.reason.value if request.reason else None,
            error_type=error.object_type if error and error.object_type else None,
            error_message=error.message if error else None,
        )
        return handler_input.response_builder.response
