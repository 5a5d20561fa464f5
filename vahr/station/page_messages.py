"""The station's page contract: `PageMessage`, the messages the station's feed pushes to its
pages (server-sent events), a union tagged on `type`.

`python -m vahr.station.contract` writes them as JSDoc typedefs, with `DRIVE_ENDS` and
`EXCHANGE_EVENTS`, into the page's `static/contract.js`, and `make lint` fails when that
file and these structs differ.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import msgspec

# The page's structs name these in annotations, which msgspec reads at run time.
from vahr.dispatch import Task  # noqa: TC001
from vahr.domain.fleet import Floor, Point, Pose  # noqa: TC001
from vahr.protocol.announcements import Announcement
from vahr.protocol.audit import AuditRecord  # noqa: TC001
from vahr.protocol.messages import Event, EventKind
from vahr.protocol.station_topics import AssistantTurn, ExperimentStatus  # noqa: TC001

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
    # The room or bay the zone stands for (a polygon), drawn and closed with it.
    area: list[Point] | None = None


class MapExtent(msgspec.Struct, frozen=True, kw_only=True):
    """A rectangle of the map frame, in metres."""

    left: float
    bottom: float
    right: float
    top: float


class FloorMap(msgspec.Struct, frozen=True, kw_only=True):
    """A floor that is a map: its picture (`image`, a PNG the station serves: occupied
    cells dark, free ones light, unknown ones clear) laid from `origin` at `resolution`
    metres a pixel, `columns` by `rows`; `known` is the part that is not unknown, which the
    page zooms to."""

    image: str
    origin: Point
    resolution: float
    columns: int
    rows: int
    known: MapExtent


class FleetView(msgspec.Struct, frozen=True, kw_only=True):
    """The fleet as the page draws it: robots, zones and the floor (`Fleet.layout`), and
    the map when the floor is one."""

    robots: list[RobotEntry]
    zones: list[ZoneEntry]
    floor: Floor
    experiment_thing: str
    map: FloorMap | None = None
    # Under this charge (percent) a robot is low: the fleet's `battery.charge_below`.
    charge_below: float = 20.0


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
    (`GET {api}/vahr/tasks`, `vahr.dispatch.Task`: what is to be done where, its
    state, the robot that took it), in its order, the zones closed now and the robots out of
    service; `available` is False when the deployment has no dispatcher to ask."""

    tasks: list[Task]
    available: bool
    closed: list[str] = []
    out_of_service: list[str] = []


class TrailMessage(msgspec.Struct, frozen=True, kw_only=True, tag="trail", tag_field="type"):
    """The latest records of the audit trail (`vahr.protocol.audit`, oldest first), sent
    when new ones came: who did what, through which channel, and what came of it."""

    records: list[AuditRecord]


class SnapshotMessage(msgspec.Struct, kw_only=True, tag="snapshot", tag_field="type"):
    """What a page starts from: the fleet, every robot, the conversation so far, the
    commands seen with their acknowledgments, the session, the announcements nobody has
    acknowledged yet (oldest first), the station's clock (ms since the epoch) for the
    page to correct its own, the fleet's task queue when the station has read it, and the
    audit trail's latest records when the station reads one."""

    fleet: FleetView
    robots: dict[str, RobotView]
    conversation: list[ConversationEntry]
    commands: dict[str, CommandMessage]
    experiment: ExperimentStatus | None
    alerts: list[AnnouncementMessage]
    server_time: float
    tasks: TasksMessage | None = None
    trail: TrailMessage | None = None


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
    | TrailMessage
)

_page_encoder = msgspec.json.Encoder()


def encode_page_message(message: PageMessage) -> bytes:
    """The JSON of one message to the pages."""
    return _page_encoder.encode(message)
