"""The messages of the operator station's topics (`topics.ASSISTANT_TURNS`,
`topics.EXPERIMENT_STATUS`, `topics.EXPERIMENT_INPUT`).

- `AssistantTurn`: one exchange with the local Alexa simulator, as `vahr say --json` prints
  it, plus where it came from (`origin`) and, for speech, what the recognizer heard.
- `StationInput`: what a participant did on the station during an experiment session: an
  `Interaction` (a click, a key press or a push-to-talk, sent when it starts and when it
  ends) or a `PuzzleInput` (pieces the observer counted). Times are the page's clock; `sent`
  lets the experiment's recorder move them onto its own clock (`on_clock`).
- `ExperimentStatus`: the running session as the station shows it: the briefing, the
  current task and the judge's live verdict per task.

Each decoder is the one place its payload is validated; errors are `ProtocolError`s.

What the station's feed pushes to its pages is the station's own (`vahr.station.page_messages`).
"""

from __future__ import annotations

from datetime import datetime, timedelta
from typing import TYPE_CHECKING, Annotated, Any, Literal

import msgspec

from vahr.protocol.decoding import LazyDecoder
from vahr.protocol.errors import ProtocolError, from_validation_error
from vahr.protocol.messages import MAX_PAYLOAD_BYTES, Timestamp, check_payload

if TYPE_CHECKING:
    from collections.abc import Mapping

Text = Annotated[str, msgspec.Meta(max_length=1_000)]
ShortText = Annotated[str, msgspec.Meta(max_length=200)]
Identifier = Annotated[
    str, msgspec.Meta(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_.:-]+$")
]
# A session name: `{participant}-{method}-trial{N}` (vahr.experiment.eventlog.session_name).
SessionName = Annotated[str, msgspec.Meta(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_-]+$")]
# Who spoke to the assistant: "say", "console", "station", "station-voice"...
ORIGIN_PATTERN = r"^[a-z][a-z0-9-]{0,31}$"
Origin = Annotated[str, msgspec.Meta(pattern=ORIGIN_PATTERN)]
# A turn carries the whole reply and every slot: larger than a command, far below AWS's limit.
MAX_TURN_BYTES = 64 * 1024


class Heard(msgspec.Struct, frozen=True, omit_defaults=True):
    """What the recognizer made of a spoken clip."""

    transcript: Text
    confidence: float
    accepted: bool
    seconds: float = 0.0


class AssistantTurn(msgspec.Struct, frozen=True, kw_only=True, omit_defaults=True):
    """One exchange with the assistant: utterance in, reply out, commands it published."""

    utterance: Text
    speech: Text
    intent: str | None = None
    slots: dict[str, dict[str, str | None]] = {}
    commands: list[str] = []
    latency_ms: float = 0.0
    session_open: bool = False
    request_type: str = "IntentRequest"
    reprompt: Text | None = None
    # Who spoke: "say" (vahr say, the HTTP API), "console", "station", "station-voice"...
    origin: Origin = "say"
    heard: Heard | None = None
    at: Timestamp | None = None


class Interaction(msgspec.Struct, frozen=True, kw_only=True, tag="interaction", tag_field="kind"):
    """A click, key press or push-to-talk on the station, sent when it starts and when it
    ends (same `id`). The end says what came of it: the commands it sent, or for a question
    to the assistant (`asks`) the reply; `counts` is False for input that sends nothing by
    design (selecting a robot), which is interaction time but not communication."""

    session: SessionName
    id: Identifier
    phase: Literal["started", "ended"]
    channel: Literal["click", "key", "voice"]
    at: Timestamp
    sent: Timestamp
    text: ShortText = ""
    commands: Annotated[list[Identifier], msgspec.Meta(max_length=16)] = []
    counts: bool = True
    asks: bool = False
    speech: Text | None = None
    intent: ShortText | None = None
    error: ShortText | None = None


class PuzzleInput(msgspec.Struct, frozen=True, kw_only=True, tag="puzzle", tag_field="kind"):
    """Puzzle pieces the observer counted (a negative count corrects a miscount)."""

    session: SessionName
    count: Annotated[int, msgspec.Meta(ge=-20, le=20)]
    at: Timestamp
    sent: Timestamp


StationInput = Interaction | PuzzleInput


TaskState = Literal["waiting", "running", "success", "failure"]


class ExperimentTaskStatus(msgspec.Struct, frozen=True, omit_defaults=True):
    """One task as the judge sees it now: not started, running (with the verdict so far),
    or ended with success or failure and why."""

    state: TaskState
    reason: Text = ""
    title: ShortText = ""
    started_at: Timestamp | None = None
    ended_at: Timestamp | None = None


class ExperimentStatus(msgspec.Struct, frozen=True, kw_only=True, omit_defaults=True):
    """The running session for the station (retained on `topics.EXPERIMENT_STATUS`).

    The weather is left out on purpose: a keyboard-and-mouse participant learns it by
    asking the assistant, and the station shows only what was answered.
    """

    session: SessionName
    participant: ShortText
    method: Literal["vahr", "keyboard"]
    trial: int
    simulated: bool = False
    assignments: dict[str, str] = {}
    task: Literal["I", "II", "III"] | None = None
    tasks: dict[str, ExperimentTaskStatus] = {}
    # The command actions the method may send in the current task (the paper's procedure).
    allowed: list[str] = []
    puzzle: int = 0
    # The task III LED on the floor (it lights when the task succeeds).
    led_on: bool = False
    started_at: Timestamp | None = None
    ended: bool = False
    at: Timestamp | None = None


_turn_decoder: LazyDecoder[AssistantTurn] = LazyDecoder(AssistantTurn)
_input_decoder: LazyDecoder[StationInput] = LazyDecoder(StationInput)
_status_decoder: LazyDecoder[ExperimentStatus] = LazyDecoder(ExperimentStatus)


def _decode(decoder: LazyDecoder[Any], payload: bytes, limit: int) -> Any:
    if len(payload) > limit:
        raise ProtocolError("payload", f"is {len(payload)} bytes; the limit is {limit}")
    try:
        return decoder.decode(payload)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise from_validation_error(err) from err


def decode_turn(payload: bytes | bytearray | memoryview) -> AssistantTurn:
    result: AssistantTurn = _decode(_turn_decoder, bytes(payload), MAX_TURN_BYTES)
    return result


def decode_station_input(payload: bytes | bytearray | memoryview) -> StationInput:
    result: StationInput = _decode(_input_decoder, check_payload(payload), MAX_PAYLOAD_BYTES)
    return result


def decode_experiment_status(payload: bytes | bytearray | memoryview) -> ExperimentStatus:
    result: ExperimentStatus = _decode(_status_decoder, check_payload(payload), MAX_PAYLOAD_BYTES)
    return result


def turn_from_message(message: Mapping[str, Any]) -> AssistantTurn:
    """A turn from its JSON object (as the in-process simulator hands it over), validated as
    `decode_turn` validates one from the broker."""
    try:
        return msgspec.convert(message, AssistantTurn)
    except msgspec.ValidationError as err:
        raise from_validation_error(err) from err


def on_clock(at: datetime, sent: datetime, received: datetime) -> datetime:
    """`at` (the page's clock) on the receiver's clock: the page's clock may be off by
    minutes (a tablet), so the time from `at` to `sent` is kept and the whole moved to end
    at `received`. The few milliseconds the message travelled are counted as part of it."""
    lead: timedelta = max(sent - at, timedelta(0))
    return received - lead
