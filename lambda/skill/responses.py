"""Building responses: answers that end or continue the session, and slot elicitation.

A one-shot request ("Alexa, ask robot fleet to ...") ends the session after the answer; a
session the person opened ("Alexa, open robot fleet") stays open and asks what is next.
A dialog in progress always stays open.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_model.dialog import ElicitSlotDirective

from skill import prompts

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import IntentRequest, Response

# Set by the LaunchRequest handler: the person opened the skill and expects a conversation.
CONVERSATION = "conversation"


def in_conversation(handler_input: HandlerInput) -> bool:
    if handler_input.request_envelope.session is None:
        return False
    attributes = handler_input.attributes_manager.session_attributes or {}
    return bool(attributes.get(CONVERSATION))


def start_conversation(handler_input: HandlerInput) -> None:
    """Remember, for the rest of the session, that the person opened the skill."""
    if handler_input.request_envelope.session is None:
        return
    attributes = handler_input.attributes_manager.session_attributes
    if attributes is None:
        attributes = handler_input.attributes_manager.session_attributes = {}
    attributes[CONVERSATION] = True


def answer(handler_input: HandlerInput, speech: str) -> Response:
    """Speak `speech`; in a conversation, also ask what is next and keep listening."""
    builder = handler_input.response_builder
    if in_conversation(handler_input):
        return builder.speak(f"{speech} {prompts.NEXT}").ask(prompts.NEXT).response
    return builder.speak(speech).set_should_end_session(True).response


def ask(handler_input: HandlerInput, speech: str, reprompt: str) -> Response:
    """Speak and keep the session open for the answer."""
    return handler_input.response_builder.speak(speech).ask(reprompt).response


def end(handler_input: HandlerInput, speech: str) -> Response:
    return handler_input.response_builder.speak(speech).set_should_end_session(True).response


def elicit(handler_input: HandlerInput, slot_name: str, question: str) -> Response:
    """Ask for one slot (Dialog.ElicitSlot), forgetting any value that did not resolve."""
    request: IntentRequest = handler_input.request_envelope.request  # type: ignore[assignment]
    intent = request.intent
    assert intent is not None
    slot = (intent.slots or {}).get(slot_name)
    if slot is not None:
        slot.value = None
        slot.resolutions = None
        slot.slot_value = None
    return (
        handler_input.response_builder.speak(question)
        .ask(question)
        .add_directive(ElicitSlotDirective(updated_intent=intent, slot_to_elicit=slot_name))
        .response
    )
