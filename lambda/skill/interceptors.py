"""Request and response interceptors: the request's language, the per-request correlation
id and the log lines."""

from __future__ import annotations

import time
import uuid
from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import (
    AbstractRequestInterceptor,
    AbstractResponseInterceptor,
)

from skill.catalog import use_locale
from skill.logs import correlation_id, log_event

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

CORRELATION_ID = "correlation_id"
STARTED = "started"


class LocaleInterceptor(AbstractRequestInterceptor):
    """Answer in the request's locale (`request.locale`, "de-DE"), English when the skill has
    no catalog for it: every `prompts.NAME` of this request is then that locale's message."""

    def process(self, handler_input: HandlerInput) -> None:
        request = handler_input.request_envelope.request
        use_locale(getattr(request, "locale", None))


class CorrelationIdInterceptor(AbstractRequestInterceptor):
    """Give the request a correlation id (Alexa's request id) for every log line it causes."""

    def process(self, handler_input: HandlerInput) -> None:
        request = handler_input.request_envelope.request
        value = (request.request_id if request is not None else None) or uuid.uuid4().hex
        correlation_id.set(value)
        attributes = handler_input.attributes_manager.request_attributes
        attributes[CORRELATION_ID] = value
        attributes[STARTED] = time.perf_counter()


class RequestLogInterceptor(AbstractRequestInterceptor):
    """Log what arrived: request type, intent, slot values and dialog state."""

    def process(self, handler_input: HandlerInput) -> None:
        request = handler_input.request_envelope.request
        intent = getattr(request, "intent", None)
        slots = {
            name: slot.value for name, slot in ((intent.slots or {}) if intent else {}).items()
        }
        dialog_state = getattr(request, "dialog_state", None)
        log_event(
            "request",
            type=request.object_type if request is not None else None,
            intent=intent.name if intent else None,
            slots=slots,
            dialog_state=dialog_state.value if dialog_state else None,
        )


class ResponseLogInterceptor(AbstractResponseInterceptor):
    """Log what the skill said and how long the request took."""

    def process(self, handler_input: HandlerInput, response: Response | None) -> None:
        started = handler_input.attributes_manager.request_attributes.get(STARTED)
        elapsed = (
            round((time.perf_counter() - started) * 1000, 1) if isinstance(started, float) else None
        )
        speech = response.output_speech if response else None
        log_event(
            "response",
            speech=getattr(speech, "ssml", None),
            end_session=response.should_end_session if response else None,
            elapsed_ms=elapsed,
        )
