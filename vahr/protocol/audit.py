"""The audit trail's record: one per command (or question) from every channel, chained.

Every record says when, who (Alexa's id, the person's name and role), through which channel
(`CHANNELS`), the words said where the channel has them (Alexa gives a skill only the
intent and its slots), the intent and its slots, the robots and command ids, and the
outcome (`Outcome`). The trail is append-only: record `seq` n carries `prev`, the hash of
record n-1 (`GENESIS` for the first), and `hash`, the SHA-256 of its own canonical JSON:

    every field but `hash`, keys sorted, no whitespace, UTF-8 (Python's
    `json.dumps(fields, sort_keys=True, separators=(",", ":"), ensure_ascii=False)`)

so anyone can recompute it. A record edited no longer matches its hash; one removed, or
two swapped, breaks the chain of `prev`; the last ones removed no longer match the trail's
head (`TrailHead`, kept beside the records by both stores). `verify` finds each.

The same records are in SQLite on one machine and in DynamoDB on AWS, served by
`GET {api}/vahr/audit` and printed by `vahr audit`.
"""

from __future__ import annotations

import hashlib
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Annotated, Any, Literal

import msgspec

from vahr.protocol.decoding import LazyDecoder
from vahr.protocol.errors import from_validation_error

if TYPE_CHECKING:
    from collections.abc import Callable

# How a command reached the robots. `alexa`: an Echo or `vahr say`; `station-voice`:
# push-to-talk at the station; `station`: typed at the station (`station-weather`: its
# weather button); `station-panel`: the station's keyboard-and-mouse panel; `api`: the
# tasks API (`POST {api}/vahr/tasks`) called by a program; `dispatcher`: the dispatcher
# giving a queued task to a robot that came free; `announcer`: what the assistant said by
# itself; `robot`: a robot asking the assistant (the weather).
CHANNELS = (
    "alexa",
    "station-voice",
    "station",
    "station-weather",
    "station-panel",
    "api",
    "dispatcher",
    "announcer",
    "robot",
)
Channel = Annotated[str, msgspec.Meta(pattern=r"^[a-z][a-z0-9-]{0,31}$")]

# sent: published or handed to the dispatcher; confirmed: sent after the person's yes;
# refused: the person's role does not allow it (nothing sent); asked: a yes was asked for
# first (nothing sent yet); cancelled: not confirmed (a no, anything else, the session
# ended: nothing sent); failed: it could not be sent (the robots or the dispatcher
# unreachable, refused by the dispatcher); answered: a question was answered; unsent: a
# command that ended with nothing to send (nothing to undo, no robot free).
Outcome = Literal[
    "sent", "confirmed", "refused", "asked", "cancelled", "failed", "answered", "unsent"
]
OUTCOMES: tuple[Outcome, ...] = (
    "sent",
    "confirmed",
    "refused",
    "asked",
    "cancelled",
    "failed",
    "answered",
    "unsent",
)
GENESIS = "0" * 64
Hash = Annotated[str, msgspec.Meta(pattern=r"^[0-9a-f]{64}$")]
Short = Annotated[str, msgspec.Meta(max_length=255)]
Words = Annotated[str, msgspec.Meta(max_length=1000)]


class AuditEntry(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """What happened, before the trail numbers and chains it."""

    time: str
    who: Short
    name: Short | None = None
    role: Short | None = None
    channel: Channel
    words: Words | None = None
    intent: Short | None = None
    slots: dict[Short, Short | None] = {}
    robots: list[Short] = []
    commands: list[Short] = []
    outcome: Outcome
    reason: Words | None = None


class AuditRecord(AuditEntry, frozen=True, kw_only=True):
    """An entry in the trail: its number, the hash of the one before, and its own."""

    seq: Annotated[int, msgspec.Meta(ge=1)]
    prev: Hash
    hash: Hash


class TrailHead(msgspec.Struct, frozen=True):
    """The trail's last record: its number and hash (kept apart from the records)."""

    seq: int
    hash: str


# CSV columns of `vahr audit --csv`, in order.
CSV_COLUMNS = (
    "seq",
    "time",
    "who",
    "name",
    "role",
    "channel",
    "words",
    "intent",
    "slots",
    "robots",
    "commands",
    "outcome",
    "reason",
    "prev",
    "hash",
)

_encoder = msgspec.json.Encoder(order="sorted")
_record_decoder: LazyDecoder[AuditRecord] = LazyDecoder(AuditRecord)


def now() -> str:
    """The time as records keep it: RFC 3339, UTC, milliseconds."""
    return datetime.now(UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")


def record_hash(fields: dict[str, Any]) -> str:
    """The SHA-256 of a record's fields (all but `hash`) in canonical JSON."""
    body = {name: value for name, value in fields.items() if name != "hash"}
    return hashlib.sha256(_encoder.encode(body)).hexdigest()


def chained(entry: AuditEntry, head: TrailHead | None) -> AuditRecord:
    """`entry` as the record after `head` (the first record when the trail is empty)."""
    fields = msgspec.to_builtins(entry)
    fields["seq"] = 1 if head is None else head.seq + 1
    fields["prev"] = GENESIS if head is None else head.hash
    fields["hash"] = record_hash(fields)
    return msgspec.convert(fields, AuditRecord)


def record_from_json(data: bytes | str) -> AuditRecord:
    try:
        return _record_decoder.decode(data)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise from_validation_error(err) from err


def record_from_builtins(data: Any) -> AuditRecord:
    try:
        return msgspec.convert(data, AuditRecord)
    except msgspec.ValidationError as err:
        raise from_validation_error(err) from err


def entry_from_builtins(data: Any) -> AuditEntry:
    """An entry a client sent (`POST {api}/vahr/audit`); ProtocolError names the field."""
    try:
        return msgspec.convert(data, AuditEntry)
    except msgspec.ValidationError as err:
        raise from_validation_error(err) from err


class Fault(msgspec.Struct, frozen=True):
    """What `verify` found wrong, at which record."""

    seq: int
    reason: str

    def __str__(self) -> str:
        return f"record {self.seq}: {self.reason}"


def verify(records: list[AuditRecord], head: TrailHead | None) -> list[Fault]:
    """Every fault in a whole trail, in the order it was stored (by `seq`): a record
    edited, one missing, records out of order, the last ones removed. Empty when intact."""
    faults: list[Fault] = []
    previous: AuditRecord | None = None
    for record in records:
        expected = 1 if previous is None else previous.seq + 1
        fields = msgspec.to_builtins(record)
        if record_hash(fields) != record.hash:
            faults.append(Fault(record.seq, "its content does not match its hash (altered)"))
        if record.seq != expected:
            if record.seq > expected:
                gap = (
                    f"{expected}" if record.seq == expected + 1 else f"{expected}-{record.seq - 1}"
                )
                faults.append(Fault(record.seq, f"record {gap} before it is missing (removed)"))
            else:
                faults.append(Fault(record.seq, "it is out of order"))
        expected_prev = GENESIS if previous is None else previous.hash
        if record.prev != expected_prev and record.seq == expected:
            faults.append(
                Fault(record.seq, "it does not follow the record before it (removed or reordered)")
            )
        previous = record
    last_seq = previous.seq if previous is not None else 0
    last_hash = previous.hash if previous is not None else GENESIS
    if head is not None and (head.seq, head.hash) != (last_seq, last_hash):
        if head.seq > last_seq:
            faults.append(
                Fault(head.seq, f"the trail ends at record {last_seq}; the last are missing")
            )
        else:
            faults.append(Fault(last_seq, "the trail's head does not match its last record"))
    elif head is None and previous is not None:
        faults.append(Fault(last_seq, "the trail's head is missing"))
    return faults


class RequestSource(msgspec.Struct, frozen=True):
    """How a request reached the skill when it runs beside the assistant in one process:
    the channel and the words said. The local Alexa simulator passes it as the handler's
    context (Lambda passes its own, and the channel is then `alexa`, the words unknown)."""

    channel: Channel = "alexa"
    words: str | None = None


def channel_of(origin: str) -> str:
    """The trail's channel for a simulator turn's origin: `vahr say` and `vahr console`
    are Alexa, as an Echo would be; the station's and the robots' origins are channels."""
    return "alexa" if origin in ("say", "console") else origin


# A request to the local tasks API (`POST {api}/vahr/tasks`) carrying this header was
# recorded by its sender (the skill records its own, with the person), so the API does not
# record it again.
RECORDED_BY_HEADER = "X-Vahr-Recorded-By"


# -- the trail's items in DynamoDB: the layout every writer and reader on AWS shares --------
#
# Key `trail` (S) and `seq` (N). The records are partition `records`, in `seq` order, each
# item holding the record's JSON in `record`; item (`head`, 0) holds the last record's
# number (`last`) and `hash`. A record is appended with one transaction of two conditional
# puts (`appended_items`): the record, if its number is free, and the new head, if the head
# is still the one the record was chained to. Writers that lose a race read the new head
# and chain again (`append_chained`), so the chain never forks and nothing is overwritten.
TRAIL_RECORDS = "records"
TRAIL_HEAD = "head"
HEAD_KEY: dict[str, Any] = {"trail": {"S": TRAIL_HEAD}, "seq": {"N": "0"}}
APPEND_ATTEMPTS = 6


def appended_items(record: AuditRecord, head: TrailHead | None) -> list[dict[str, Any]]:
    """The two conditional puts (TransactItems, without the table's name) that append
    `record` after `head`."""
    stored = {
        "trail": {"S": TRAIL_RECORDS},
        "seq": {"N": str(record.seq)},
        "record": {"S": msgspec.json.encode(record).decode()},
    }
    new_head = {**HEAD_KEY, "last": {"N": str(record.seq)}, "hash": {"S": record.hash}}
    if head is None:
        head_condition: dict[str, Any] = {"ConditionExpression": "attribute_not_exists(trail)"}
    else:
        head_condition = {
            "ConditionExpression": "#last = :last AND #hash = :hash",
            "ExpressionAttributeNames": {"#last": "last", "#hash": "hash"},
            "ExpressionAttributeValues": {
                ":last": {"N": str(head.seq)},
                ":hash": {"S": head.hash},
            },
        }
    return [
        {"Put": {"Item": stored, "ConditionExpression": "attribute_not_exists(trail)"}},
        {"Put": {"Item": new_head, **head_condition}},
    ]


def head_from_item(item: dict[str, Any] | None) -> TrailHead | None:
    if item is None:
        return None
    return TrailHead(int(item["last"]["N"]), str(item["hash"]["S"]))


def record_from_item(item: dict[str, Any]) -> AuditRecord:
    """A records item as the record it holds; its key `seq` wins over the JSON's, so a
    record moved to another number reads as altered."""
    record = record_from_json(item["record"]["S"])
    key = int(item["seq"]["N"])
    return record if record.seq == key else msgspec.structs.replace(record, seq=key)


def append_chained(
    entry: AuditEntry,
    read_head: Callable[[], TrailHead | None],
    put: Callable[[AuditRecord, TrailHead | None], bool],
    *,
    attempts: int = APPEND_ATTEMPTS,
    pause: Callable[[int], None] | None = None,
) -> AuditRecord | None:
    """Chain `entry` after the head `read_head` gives and `put` it (False: another writer
    won the race); try again on the new head, up to `attempts` times. None when every
    attempt lost (the trail stayed busy)."""
    for attempt in range(attempts):
        record = chained(entry, read_head())
        if put(record, None if record.seq == 1 else TrailHead(record.seq - 1, record.prev)):
            return record
        if pause is not None:
            pause(attempt)
    return None
