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

The station's page contract follows: `PageMessage`, the messages the station's feed pushes
to its pages (server-sent events), a union tagged on `type`. `python -m vahr.station.contract`
writes them as JSDoc typedefs, with `DRIVE_ENDS` and `EXCHANGE_EVENTS`, into the page's
`static/contract.js`, and `make lint` fails when that file and these structs differ.
"""

from __future__ import annotations

from datetime import datetime, timedelta
from typing import TYPE_CHECKING, Annotated, Any, Literal

import msgspec

from vahr.protocol.announcements import Announcement
from vahr.protocol.dispatch import Task  # noqa: TC001 (msgspec reads it at run time)
from vahr.protocol.errors import ProtocolError, from_validation_error

# The page's structs name these in annotations, which msgspec reads at run time.
from vahr.protocol.fleet import Floor, Pose  # noqa: TC001
from vahr.protocol.messages import MAX_PAYLOAD_BYTES, Event, EventKind, Timestamp, check_payload

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


class TaskStatus(msgspec.Struct, frozen=True, omit_defaults=True):
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
    tasks: dict[str, TaskStatus] = {}
    # The command actions the method may send in the current task (the paper's procedure).
    allowed: list[str] = []
    puzzle: int = 0
    # The task III LED on the floor (it lights when the task succeeds).
    led_on: bool = False
    started_at: Timestamp | None = None
    ended: bool = False
    at: Timestamp | None = None


_turn_decoder = msgspec.json.Decoder(AssistantTurn)
_input_decoder = msgspec.json.Decoder(StationInput)
_status_decoder = msgspec.json.Decoder(ExperimentStatus)


def _decode(decoder: msgspec.json.Decoder[Any], payload: bytes, limit: int) -> Any:
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


# -- the page contract: what the station's feed pushes to its pages ---------------------------

# Events after which a robot is no longer driving (the page stops moving it; its progress is
# over). Not `rejected`: a rejected command never ran and the robot carries on with what it
# was doing. Not `done`: a drive ends with one of these first, and a ping answered mid-drive
# says `done` while the robot drives on.
DRIVE_ENDS: frozenset[EventKind] = frozenset(
    {"arrived", "delivered", "stopped", "stuck", "failed", "cancelled"}
)
# The robots' own exchanges with the assistant, which the conversation shows.
EXCHANGE_EVENTS: frozenset[EventKind] = frozenset({"said", "heard", "interpreted"})

# A robot's reported shadow state as the robot sent it, passed on whole: a `Reported` (the
# page shows the raw document too, so fields beyond the contract are kept).
ReportedState = Annotated[
    dict[str, Any], msgspec.Meta(extra_json_schema={"$ref": "#/$defs/Reported"})
]


class RobotEntry(msgspec.Struct, frozen=True, kw_only=True):
    """A robot as the page draws it: its spoken name, its key (1-9, None past nine robots)
    and where it starts."""

    thing: str
    name: str
    key: str | None
    start: Pose


class ZoneEntry(msgspec.Struct, frozen=True, kw_only=True):
    """A zone as the page draws it, with its key (its first letter, None if another zone
    took it)."""

    id: str
    name: str
    pose: Pose
    radius: float
    arm: Literal["loader", "unloader"] | None
    key: str | None


class FleetView(msgspec.Struct, frozen=True, kw_only=True):
    """The fleet as the page draws it: robots, zones and the floor (`Fleet.layout`)."""

    robots: list[RobotEntry]
    zones: list[ZoneEntry]
    floor: Floor
    experiment_thing: str


class RobotView(msgspec.Struct, kw_only=True):
    """What a page knows of one robot: its reported shadow and version, presence, when it
    was last seen (ms since the epoch), its last event and the progress of the drive under
    way. None until known."""

    reported: ReportedState | None
    version: int | None
    online: bool | None
    last_seen: float | None
    last_event: Event | None
    progress: Event | None


class Acknowledgment(msgspec.Struct, frozen=True):
    """A robot's first answer to a command (an event, or its shadow's `last_command`
    result) and the time from the command being seen to it."""

    event: str
    latency_ms: float


class CommandParams(msgspec.Struct, frozen=True, omit_defaults=True):
    """A command's params as seen: only those of its action are present."""

    zone: str | msgspec.UnsetType = msgspec.UNSET
    after: str | None | msgspec.UnsetType = msgspec.UNSET


class TasksMessage(msgspec.Struct, frozen=True, kw_only=True, tag="tasks", tag_field="type"):
    """The fleet's task queue, sent when it changed: every task the dispatcher lists
    (`GET {api}/vahr/tasks`, `vahr.protocol.dispatch.Task`: what is to be done where, its
    state, the robot that took it), in its order; `available` is False when the deployment
    has no dispatcher to ask."""

    tasks: list[Task]
    available: bool


class SnapshotMessage(msgspec.Struct, kw_only=True, tag="snapshot", tag_field="type"):
    """What a page starts from: the fleet, every robot, the conversation so far, the
    commands seen with their acknowledgments, the session, the announcements nobody has
    acknowledged yet (oldest first), the station's clock (ms since the epoch) for the
    page to correct its own, and the fleet's task queue when the station has read it."""

    fleet: FleetView
    robots: dict[str, RobotView]
    conversation: list[ConversationEntry]
    commands: dict[str, CommandMessage]
    experiment: ExperimentStatus | None
    alerts: list[AnnouncementMessage]
    server_time: float
    tasks: TasksMessage | None = None


class RobotChange(msgspec.Struct, kw_only=True, omit_defaults=True):
    """What changed of one robot since the page last heard of it: a field is present only
    when it changed. `reported` holds the reported state's top-level fields that changed,
    with their new values, and `removed` those that are gone: the page merges them into
    the state it has. `version` is the shadow version that brings it to; `last_event` the
    robot's latest event other than progress (an exchange with the assistant is sent as an
    `EventMessage` instead); `progress` the drive's latest progress event (None once the
    drive ended). A page applies `last_event` before `progress`: `progress` is always the
    state after both."""

    thing: str
    reported: ReportedState | msgspec.UnsetType = msgspec.UNSET
    removed: list[str] | msgspec.UnsetType = msgspec.UNSET
    version: int | msgspec.UnsetType = msgspec.UNSET
    online: bool | msgspec.UnsetType = msgspec.UNSET
    last_seen: float | None | msgspec.UnsetType = msgspec.UNSET
    progress: Event | None | msgspec.UnsetType = msgspec.UNSET
    last_event: Event | msgspec.UnsetType = msgspec.UNSET


class RobotsMessage(msgspec.Struct, frozen=True, kw_only=True, tag="robots", tag_field="type"):
    """The robots that changed since the page's last message, each once, with only what
    changed (shadow updates, presence and drive progress coalesced per robot): at most one
    of these reaches a page per frame however many robots report."""

    changes: list[RobotChange]


class EventMessage(Event, frozen=True, tag="event", tag_field="type"):
    """What a robot said, heard or understood (`EXCHANGE_EVENTS`), with when the station
    last heard from it; in the conversation, with the robots it concerns."""

    last_seen: float
    robots: list[str] = []


class CommandMessage(msgspec.Struct, kw_only=True, tag="command", tag_field="type"):
    """A command seen on a command topic (from the assistant, the console, a robot), to
    `target` (a thing, or "fleet" for every robot in `robots`); `acks` grows as robots
    answer. `seen` is when the station saw it (ms since the epoch)."""

    id: str
    target: str
    robots: list[str]
    action: str
    params: CommandParams
    source: str
    seen: float
    acks: dict[str, Acknowledgment]


class AckMessage(msgspec.Struct, frozen=True, kw_only=True, tag="ack", tag_field="type"):
    """A robot's first answer to a command, with the time it took from the command being
    seen (the acknowledgment latency the conversation shows)."""

    id: str
    thing: str
    event: str
    latency_ms: float


class TurnMessage(AssistantTurn, frozen=True, tag="turn", tag_field="type"):
    """One exchange with the assistant, with the robots it concerns."""

    robots: list[str]


class ExperimentMessage(
    msgspec.Struct, frozen=True, kw_only=True, tag="experiment", tag_field="type"
):
    """The running session, or None when none runs."""

    status: ExperimentStatus | None


class AnnouncementMessage(Announcement, frozen=True, tag="announcement", tag_field="type"):
    """What the assistant told the person unprompted (a robot stuck, failed, offline...),
    with the robots it concerns. The page shows it as an alert until someone acknowledges
    it, and in the conversation."""

    robots: list[str]


class AlertAcknowledgedMessage(
    msgspec.Struct, frozen=True, kw_only=True, tag="alert_acknowledged", tag_field="type"
):
    """Someone acknowledged an alert on a station page: these announcements (the one
    acknowledged and any other still open about the same robot and trouble) are no longer
    shown as alerts."""

    ids: list[str]


ConversationEntry = TurnMessage | CommandMessage | EventMessage | AnnouncementMessage
PageMessage = (
    SnapshotMessage
    | RobotsMessage
    | EventMessage
    | CommandMessage
    | AckMessage
    | TurnMessage
    | ExperimentMessage
    | AnnouncementMessage
    | AlertAcknowledgedMessage
    | TasksMessage
)

_page_encoder = msgspec.json.Encoder()


def encode_page_message(message: PageMessage) -> bytes:
    """The JSON of one message to the pages."""
    return _page_encoder.encode(message)
