"""A "no" to Dialog.ConfirmIntent ("Send placebot one to zone B?" "No."): whatever the
intent, nothing is sent, the reply says so and the session stays open for the request
said again (the simulator confirms a reading it is unsure of this way)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_request_type

from skill import prompts
from skill.responses import ask

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import IntentRequest, Response


class DeniedIntentHandler(AbstractRequestHandler):
    """Any IntentRequest whose intent the person denied: send nothing."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        if not is_request_type("IntentRequest")(handler_input):
            return False
        request: IntentRequest = handler_input.request_envelope.request  # type: ignore[assignment]
        status = request.intent.confirmation_status if request.intent else None
        return status is not None and status.value == "DENIED"

    def handle(self, handler_input: HandlerInput) -> Response:
        return ask(handler_input, prompts.INTENT_DENIED, prompts.FALLBACK_REPROMPT)
