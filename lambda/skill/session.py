"""The last command the skill sent in this conversation, kept in the session's attributes.

"No, zone b", "I meant placebot two" and "cancel that" act on it: a correction sends the
same action again to the right robot or zone (the new command preempts the old one), an
undo stops that robot only. Only commands that move a robot are kept: a stop is never
undone. The local assistant keeps this one attribute a little past the session's end for
the same speaker (`vahr.protocol.conversation`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from vahr.protocol.conversation import LAST_COMMAND_ATTRIBUTE

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput

    from skill.commands import Publication

# The actions a correction can redirect or an undo can stop.
CORRECTABLE = ("navigate", "deliver", "weather_delivery")


class SentCommand(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """What the skill sent last: to which robot (a thing, or the fleet), what, and where."""

    robot: str
    action: str
    id: str
    zone: str | None = None


def _attributes(handler_input: HandlerInput) -> dict[str, object] | None:
    if handler_input.request_envelope.session is None:
        return None
    manager = handler_input.attributes_manager
    if manager.session_attributes is None:
        manager.session_attributes = {}
    attributes: dict[str, object] | None = manager.session_attributes
    return attributes


def remember(handler_input: HandlerInput, item: Publication) -> None:
    """Keep `item` as the command a correction or undo refers to (motion commands only)."""
    attributes = _attributes(handler_input)
    if attributes is None or item.command.action not in CORRECTABLE:
        return
    zone = getattr(item.command.params, "zone", None)
    last = SentCommand(
        robot=item.target,
        action=item.command.action,
        id=item.command.id,
        zone=zone if isinstance(zone, str) else None,
    )
    attributes[LAST_COMMAND_ATTRIBUTE] = msgspec.to_builtins(last)


def recall(handler_input: HandlerInput) -> SentCommand | None:
    """The last command, or None when there is none (or what is stored is not one)."""
    attributes = _attributes(handler_input) or {}
    stored = attributes.get(LAST_COMMAND_ATTRIBUTE)
    if stored is None:
        return None
    try:
        return msgspec.convert(stored, SentCommand)
    except msgspec.ValidationError:
        # Attributes come back from the device: a damaged one is no command to act on.
        return None


def forget(handler_input: HandlerInput) -> None:
    attributes = _attributes(handler_input)
    if attributes is not None:
        attributes.pop(LAST_COMMAND_ATTRIBUTE, None)
