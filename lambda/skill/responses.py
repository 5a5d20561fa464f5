"""Building responses: answers that end or continue the session, and slot elicitation.

A one-shot request ("Alexa, ask robot fleet to ...") ends the session after the answer; a
session the person opened ("Alexa, open robot fleet") stays open and asks what is next.
A dialog in progress always stays open.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_model import Slot, SlotConfirmationStatus
from ask_sdk_model.dialog import ConfirmIntentDirective, ConfirmSlotDirective, ElicitSlotDirective

from skill import prompts

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Intent, IntentRequest, Response

# Set by the LaunchRequest handler: the person opened the skill and expects a conversation.
CONVERSATION = "conversation"
# How many questions in a row the skill has asked for one command. After MAX_QUESTIONS it
# stops asking: a person who keeps being misheard needs a way out, not another question.
QUESTIONS = "questions"
MAX_QUESTIONS = 3


def plain_text(speech: str) -> str:
    """Escape text for SSML: a robot's reason or a heard value may hold `&`, `<` or `>`."""
    return speech.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def _attributes(handler_input: HandlerInput) -> dict[str, object] | None:
    if handler_input.request_envelope.session is None:
        return None
    manager = handler_input.attributes_manager
    if manager.session_attributes is None:
        manager.session_attributes = {}
    attributes: dict[str, object] | None = manager.session_attributes
    return attributes


def in_conversation(handler_input: HandlerInput) -> bool:
    attributes = _attributes(handler_input) or {}
    return bool(attributes.get(CONVERSATION))


def start_conversation(handler_input: HandlerInput) -> None:
    """Remember, for the rest of the session, that the person opened the skill."""
    attributes = _attributes(handler_input)
    if attributes is not None:
        attributes[CONVERSATION] = True


def answer(handler_input: HandlerInput, speech: str) -> Response:
    """Speak `speech`; in a conversation, also ask what is next and keep listening."""
    attributes = _attributes(handler_input)
    if attributes is not None:
        attributes.pop(QUESTIONS, None)
    builder = handler_input.response_builder
    if in_conversation(handler_input):
        return builder.speak(plain_text(f"{speech} {prompts.NEXT}")).ask(prompts.NEXT).response
    return builder.speak(plain_text(speech)).set_should_end_session(True).response


def ask(handler_input: HandlerInput, speech: str, reprompt: str) -> Response:
    """Speak and keep the session open for the answer."""
    builder = handler_input.response_builder
    return builder.speak(plain_text(speech)).ask(plain_text(reprompt)).response


def end(handler_input: HandlerInput, speech: str) -> Response:
    builder = handler_input.response_builder
    return builder.speak(plain_text(speech)).set_should_end_session(True).response


def may_ask_again(handler_input: HandlerInput) -> bool:
    """Count one more question for this command; False once MAX_QUESTIONS were asked."""
    attributes = _attributes(handler_input)
    if attributes is None:
        return True
    asked = questions_asked(handler_input) + 1
    attributes[QUESTIONS] = asked
    return asked <= MAX_QUESTIONS


def questions_asked(handler_input: HandlerInput) -> int:
    """How many questions the skill has asked for this command so far."""
    attributes = _attributes(handler_input) or {}
    return int(str(attributes.get(QUESTIONS, 0)))


def _intent_with_slot(handler_input: HandlerInput, slot_name: str) -> tuple[Intent, Slot]:
    """The request's intent, to send back as the directive's updated intent, and its slot
    `slot_name`, added when the request left it out (the directive must carry it)."""
    request: IntentRequest = handler_input.request_envelope.request  # type: ignore[assignment]
    intent = request.intent
    assert intent is not None
    if intent.slots is None:
        intent.slots = {}
    slot = intent.slots.setdefault(
        slot_name, Slot(name=slot_name, confirmation_status=SlotConfirmationStatus.NONE)
    )
    return intent, slot


def elicit(
    handler_input: HandlerInput, slot_name: str, question: str, reprompt: str | None = None
) -> Response:
    """Ask for one slot (Dialog.ElicitSlot), forgetting any value that did not resolve; the
    reprompt (what Alexa says when it did not get the answer) is the question unless given."""
    intent, slot = _intent_with_slot(handler_input, slot_name)
    slot.value = None
    slot.resolutions = None
    slot.slot_value = None
    return (
        handler_input.response_builder.speak(plain_text(question))
        .ask(plain_text(reprompt or question))
        .add_directive(ElicitSlotDirective(updated_intent=intent, slot_to_elicit=slot_name))
        .response
    )


def confirm_slot(
    handler_input: HandlerInput, slot_name: str, value: str, question: str
) -> Response:
    """Ask a yes-or-no question about one slot (Dialog.ConfirmSlot), with `value` filled in
    as what the skill takes it to be; the answer comes back as the slot's
    confirmationStatus."""
    intent, slot = _intent_with_slot(handler_input, slot_name)
    slot.value = value
    slot.resolutions = None
    slot.slot_value = None
    slot.confirmation_status = SlotConfirmationStatus.NONE
    return (
        handler_input.response_builder.speak(plain_text(question))
        .ask(plain_text(question))
        .add_directive(ConfirmSlotDirective(updated_intent=intent, slot_to_confirm=slot_name))
        .response
    )


def confirm_intent(handler_input: HandlerInput, question: str) -> Response:
    """Ask a yes-or-no question about the whole request (Dialog.ConfirmIntent); the answer
    comes back as the same intent with confirmationStatus CONFIRMED or DENIED."""
    request: IntentRequest = handler_input.request_envelope.request  # type: ignore[assignment]
    assert request.intent is not None
    return (
        handler_input.response_builder.speak(plain_text(question))
        .ask(plain_text(question))
        .add_directive(ConfirmIntentDirective(updated_intent=request.intent))
        .response
    )
