"""ASK request envelopes, built with ask-sdk-model's own classes and serializer, so the
skill receives exactly the JSON shape Alexa sends (tests/events/ holds recorded ones).

A slot whose words fit several values about equally carries them all, in the order of
preference, as the values of one ER_SUCCESS_MATCH resolution (as Alexa resolves "robot"
to either robot). While a dialog confirms a slot or the whole intent, the person's yes or
no travels as the slot's or the intent's confirmationStatus (CONFIRMED, DENIED).
"""

from __future__ import annotations

import uuid
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

from ask_sdk_core.serialize import DefaultSerializer
from ask_sdk_model import (
    Application,
    Context,
    Device,
    DialogState,
    Intent,
    IntentConfirmationStatus,
    IntentRequest,
    LaunchRequest,
    Person,
    RequestEnvelope,
    Session,
    SessionEndedReason,
    SessionEndedRequest,
    Slot,
    SlotConfirmationStatus,
    SupportedInterfaces,
    User,
)
from ask_sdk_model.interfaces.system import SystemState
from ask_sdk_model.slu.entityresolution import (
    Resolution,
    Resolutions,
    Status,
    StatusCode,
    Value,
    ValueWrapper,
)

if TYPE_CHECKING:
    from collections.abc import Mapping

    from ask_sdk_model import Request

    from vahr.assistant.nlu import SlotValue, Understanding

LOCALE = "en-US"
_serializer = DefaultSerializer()


class Identity:
    """The skill, user and device a simulated Echo speaks for (stable for a run)."""

    def __init__(self, skill_id: str | None = None) -> None:
        self.skill_id = skill_id or f"amzn1.ask.skill.{uuid.uuid4()}"
        self.user_id = f"amzn1.ask.account.VAHRLOCAL{uuid.uuid4().hex.upper()}"
        self.device_id = f"amzn1.ask.device.VAHRLOCAL{uuid.uuid4().hex.upper()}"


def _request_id() -> str:
    return f"amzn1.echo-api.request.{uuid.uuid4()}"


def _now() -> datetime:
    return datetime.now(UTC).replace(microsecond=0)


def launch_request() -> LaunchRequest:
    return LaunchRequest(request_id=_request_id(), timestamp=_now(), locale=LOCALE)


def session_ended_request(reason: str = "USER_INITIATED") -> SessionEndedRequest:
    return SessionEndedRequest(
        request_id=_request_id(),
        timestamp=_now(),
        locale=LOCALE,
        reason=SessionEndedReason(reason),
    )


def slot(
    identity: Identity, value: SlotValue | None, name: str, confirmation: str = "NONE"
) -> Slot:
    """A slot as Alexa fills it: empty, or with a value and its entity resolution."""
    status = SlotConfirmationStatus(confirmation)
    if value is None:
        return Slot(name=name, confirmation_status=status)
    authority = f"amzn1.er-authority.echo-sdk.{identity.skill_id}.{value.type}"
    if value.resolved:
        matched = [(value.id, value.canonical), *value.alternatives]
        resolution = Resolution(
            authority=authority,
            status=Status(code=StatusCode.ER_SUCCESS_MATCH),
            values=[ValueWrapper(value=Value(name=n, id=i)) for i, n in matched],
        )
    else:
        resolution = Resolution(
            authority=authority, status=Status(code=StatusCode.ER_SUCCESS_NO_MATCH)
        )
    return Slot(
        name=name,
        value=value.spoken,
        confirmation_status=status,
        resolutions=Resolutions(resolutions_per_authority=[resolution]),
    )


def intent_request(
    identity: Identity,
    understanding: Understanding,
    dialog_state: str | None,
    *,
    intent_confirmation: str = "NONE",
    slot_confirmations: Mapping[str, str] | None = None,
) -> IntentRequest:
    """An IntentRequest for `understanding`; the confirmations are the person's answers to
    Dialog.ConfirmIntent and Dialog.ConfirmSlot (NONE, CONFIRMED or DENIED)."""
    confirmations = slot_confirmations or {}
    slots = {
        name: slot(identity, understanding.slots.get(name), name, confirmations.get(name, "NONE"))
        for name in understanding.declared or tuple(understanding.slots)
    }
    return IntentRequest(
        request_id=_request_id(),
        timestamp=_now(),
        locale=LOCALE,
        dialog_state=DialogState(dialog_state) if dialog_state else None,
        intent=Intent(
            name=understanding.intent,
            slots=slots or None,
            confirmation_status=IntentConfirmationStatus(intent_confirmation),
        ),
    )


def envelope(
    identity: Identity,
    request: Request,
    *,
    session_id: str,
    new: bool,
    attributes: dict[str, Any],
    user_id: str | None = None,
    person_id: str | None = None,
) -> dict[str, Any]:
    """The whole request envelope as the JSON object a Lambda receives: from `user_id`'s
    Alexa account (default: the identity's), and `person_id` when Alexa recognised the
    speaker's voice (Alexa personalization: `context.System.person`)."""
    application = Application(application_id=identity.skill_id)
    user = User(user_id=user_id or identity.user_id)
    built = RequestEnvelope(
        version="1.0",
        session=Session(
            new=new,
            session_id=session_id,
            application=application,
            attributes=attributes,
            user=user,
        ),
        context=Context(
            system=SystemState(
                application=application,
                user=user,
                person=Person(person_id=person_id) if person_id else None,
                device=Device(
                    device_id=identity.device_id, supported_interfaces=SupportedInterfaces()
                ),
                api_endpoint="https://api.amazonalexa.com",
            )
        ),
        request=request,
    )
    serialized = _serializer.serialize(built)
    if not isinstance(serialized, dict):
        raise TypeError("a request envelope serializes to a JSON object")
    return serialized
