"""The one error type that decoding raises, and its translation from msgspec's errors."""

from __future__ import annotations

import re

import msgspec

# msgspec reports the failing location as a JSON path such as `$.params.zone` or `$[0]`.
# Compiled on first use (re's cache): most importers never see a validation error.
_AT_PATH = r"(?s)^(?P<reason>.*?)(?: - at `\$(?P<path>[^`]*)`)?$"
_MISSING = r"^Object missing required field `(?P<field>[^`]+)`$"
_UNKNOWN = r"^Object contains unknown field `(?P<field>[^`]+)`$"
_EXPECTED = r"^Expected `(?P<want>[^`]+)`, got `(?P<got>[^`]+)`$"
_TAG = r"^Invalid value '?(?P<value>[^']*)'?$"


MAX_SHOWN = 40


def shown(value: object) -> str:
    """A value as an error quotes it: on one line (control characters escaped) and at most
    MAX_SHOWN characters, so a hostile payload cannot stretch or split the message."""
    text = _one_line(str(value))
    return text if len(text) <= MAX_SHOWN else text[: MAX_SHOWN - 1] + "…"


def _one_line(text: str) -> str:
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode() for c in text)


class ProtocolError(ValueError):
    """A payload that breaks the wire contract.

    `field` is a dotted path into the message (`params.zone`, or `payload` for the whole
    thing) and `reason` says what is wrong in words a user can act on. `str(error)` is the
    one-line form `field: reason` used in `rejected` events and CLI errors.
    """

    def __init__(self, field: str, reason: str) -> None:
        field, reason = _one_line(field), _one_line(reason)
        super().__init__(f"{field}: {reason}")
        self.field = field
        self.reason = reason


def _join(path: str, field: str) -> str:
    return f"{path}.{field}" if path else field


def from_validation_error(err: msgspec.ValidationError | msgspec.DecodeError) -> ProtocolError:
    """Translate a msgspec error into a ProtocolError naming the field in dotted form."""
    match = re.match(_AT_PATH, str(err))
    reason = match["reason"] if match else str(err)
    path = (match["path"] or "") if match else ""
    path = re.sub(r"\[(\d+)\]", r".\1", path).lstrip(".")
    if found := re.match(_MISSING, reason):
        return ProtocolError(_join(path, found["field"]), "is required but missing")
    if found := re.match(_UNKNOWN, reason):
        # The name is the sender's own: shown cut short, like any value a payload carries.
        return ProtocolError(_join(path, shown(found["field"])), "is not a known field")
    if found := re.match(_EXPECTED, reason):
        return ProtocolError(path or "payload", f"expected {found['want']}, got {found['got']}")
    if isinstance(err, msgspec.DecodeError) and not path:
        return ProtocolError("payload", f"is not valid JSON ({reason.lower()})")
    if path == "action" and (found := re.match(_TAG, reason)):
        return ProtocolError("action", f"'{shown(found['value'])}' is not a known action")
    return ProtocolError(path or "payload", reason[:1].lower() + reason[1:])
