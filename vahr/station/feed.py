"""What the station's pages show, kept from the broker's messages and pushed to every page.

`Feed` is transport-free: an MQTT client routes messages to its `on_*` handlers (`routes`),
and each page holds a `Subscriber` that receives first a snapshot of everything, then one
message per change, in the order the feed saw them. Messages are JSON objects with a
`type`, each a struct of `vahr.station.page_messages` (`PageMessage`), which the page knows as
the typedefs of `static/contract.js`:

- `snapshot`: the fleet and its floor, every robot (reported shadow, presence, the last
  event, the progress of the drive under way), the conversation so far, the commands seen
  and their acknowledgments, the experiment session;
- `robots`: the robots that changed since the page's last message, each once with only
  what changed: its reported fields after an accepted shadow update (and the version),
  presence, its latest event and the progress of its drive (`RobotChange`;
  `vahr.station.changes`);
- `event`: what a robot said, heard or understood (`EXCHANGE_EVENTS`, the conversation's);
  anything else a robot did (accepted, progress, arrived...) is part of its change in
  `robots`;
- `command`: a command seen on a command topic (from the assistant, the console, a robot);
- `ack`: the first answer of a robot to a command, with the time it took from the command
  being seen here (the acknowledgment latency the conversation shows);
- `turn`: one exchange with the assistant;
- `experiment`: the running session (or `null` when none);
- `announcement`: what the assistant told the person unprompted (a robot stuck, failed,
  offline; `topics.ASSISTANT_ANNOUNCEMENTS`), shown as an alert until acknowledged;
- `alert_acknowledged`: someone acknowledged an alert on a page (`acknowledge`): the
  announcement and any other still open about the same robot and trouble;
- `tasks`: the fleet's task queue and who took which task, when it changed (`set_tasks`,
  fed by `vahr.station.task_queue.TaskPoller` from the dispatcher's `GET {api}/vahr/tasks`);
- `trail`: the audit trail's latest records, when new ones came (`add_records`, fed by
  `vahr.station.trail_feed.TrailPoller`).

Acknowledgments are the station's, not one page's: every page stops showing the alert, and
a page that reloads does not raise it again.

Robots' changes are coalesced per page: a robot that changes again before the page took
its last change has the two merged (`Subscriber.push_change`), and the stream writes at
most one batch a frame (`server.FRAME_S`), so a thousand robots reporting cost the page one
message a frame, not thousands.

Nothing here waits on a page: a page that falls `SUBSCRIBER_LIMIT` messages behind is
dropped, and its browser reconnects and starts again from a snapshot.
"""

from __future__ import annotations

import json
import logging
import threading
import time
from collections import OrderedDict, deque
from pathlib import PurePath
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.domain import FLEET_GROUP
from vahr.domain.fleet import SPOKEN_LOCALE, spoken_in, zone_name_in
from vahr.navigation import load_floor
from vahr.protocol import ProtocolError, decode_command, decode_event, decode_presence, topics
from vahr.protocol.announcements import Announcement, decode_announcement
from vahr.protocol.station_topics import (
    AssistantTurn,
    ExperimentStatus,
    decode_experiment_status,
    decode_turn,
    turn_from_message,
)
from vahr.station.changes import merge, own, reported_change
from vahr.station.floor_picture import FloorPicture, floor_picture
from vahr.station.page_messages import (
    DRIVE_ENDS,
    EXCHANGE_EVENTS,
    AckMessage,
    Acknowledgment,
    AlertAcknowledgedMessage,
    AnnouncementMessage,
    CommandMessage,
    CommandParams,
    ConversationEntry,
    EventMessage,
    ExperimentMessage,
    FleetView,
    PageMessage,
    RobotChange,
    RobotEntry,
    RobotsMessage,
    RobotView,
    SnapshotMessage,
    TasksMessage,
    TrailMessage,
    TurnMessage,
    ZoneEntry,
    encode_page_message,
)

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from vahr.domain import Fleet
    from vahr.protocol.audit import AuditRecord

log = logging.getLogger(__name__)

# Messages a page may fall behind before it is dropped (it reconnects from a snapshot).
SUBSCRIBER_LIMIT = 20_000
# Conversation entries (turns, console commands, robots' exchanges) kept for a new page.
CONVERSATION_LIMIT = 400
# Commands whose acknowledgments are followed; older ones are forgotten.
COMMANDS_LIMIT = 1_000
# The audit trail's records a page shows: the latest ones (`vahr audit` prints them all).
TRAIL_SHOWN = 30
# Alerts kept until acknowledged; past this many the oldest is let go (the rate limit tells
# at most a few a minute, so this is hours of nobody looking).
ALERTS_LIMIT = 100
# Announcement ids remembered, so one delivered twice (QoS 1) is shown once.
ANNOUNCEMENTS_REMEMBERED = 1_000
Json = dict[str, Any]


def now_ms() -> float:
    return time.time() * 1000


class Subscriber:
    """One page's queue of encoded messages.

    A message pushed with a `key` replaces the one with the same key that the page has not
    taken yet. Robots' changes (`push_change`) wait as one `robots` message at the place of
    the first of them, each robot's merged into one: a page that falls behind gets each
    robot's latest state rather than every step of it.
    """

    def __init__(self, limit: int = SUBSCRIBER_LIMIT) -> None:
        self._limit = limit
        # Encoded messages; None marks where the robots' changes go when taken.
        self._pending: list[bytes | None] = []
        self._keyed: dict[str, int] = {}  # key -> index in _pending
        self._changes: dict[str, RobotChange] = {}
        self._ready = threading.Condition()
        self.closed = False
        self.overflowed = False

    def push(self, message: bytes, key: str | None = None) -> None:
        with self._ready:
            if self.closed:
                return
            if key is not None and key in self._keyed:
                self._pending[self._keyed[key]] = message
                return
            if self._full():
                return
            if key is not None:
                self._keyed[key] = len(self._pending)
            self._pending.append(message)
            self._ready.notify()

    def push_change(self, change: RobotChange) -> None:
        """A robot's change: merged into the one of the same robot not taken yet."""
        with self._ready:
            if self.closed:
                return
            waiting = self._changes.get(change.thing)
            if waiting is not None:
                merge(waiting, change)
                return
            if not self._changes:
                if self._full():
                    return
                self._pending.append(None)
            self._changes[change.thing] = own(change)
            self._ready.notify()

    def _full(self) -> bool:
        """Close this page's queue if it holds its limit (call with the lock held)."""
        if len(self._pending) < self._limit:
            return False
        self.overflowed = self.closed = True
        self._pending.clear()
        self._keyed.clear()
        self._changes.clear()
        self._ready.notify()
        return True

    def take(self, timeout_s: float) -> list[bytes] | None:
        """Every message waiting (after up to `timeout_s` for one); None once closed."""
        with self._ready:
            if not self._pending and not self.closed:
                self._ready.wait(timeout_s)
            if self.closed:
                return None
            taken, self._pending = self._pending, []
            changes, self._changes = self._changes, {}
            self._keyed.clear()
        robots = (
            encode_page_message(RobotsMessage(changes=list(changes.values()))) if changes else b""
        )
        return [robots if message is None else message for message in taken]

    def close(self) -> None:
        with self._ready:
            self.closed = True
            self._ready.notify()


def zone_keys(fleet: Fleet, locale: str = SPOKEN_LOCALE) -> dict[str, str]:
    """A key for each zone, a letter no other zone has: the first of its id's letters that
    is free, else of its name's ("LOADING" L, "LAB" A when L is taken). A zone left without
    one (every letter taken) is clicked."""
    keys: dict[str, str] = {}
    for zone in fleet.zones:
        letters = [c for c in zone.id + zone_name_in(zone, locale).upper() if "A" <= c <= "Z"]
        key = next((c for c in letters if c not in keys.values()), None)
        if key is not None:
            keys[zone.id] = key
    return keys


def fleet_view(
    fleet: Fleet, locale: str = SPOKEN_LOCALE, picture: FloorPicture | None = None
) -> FleetView:
    """The fleet as the page draws it: robots with their keys, zones with theirs, the floor
    (with the map's size, and where its `picture` lies, when the floor is a map); names in
    `locale`, as the assistant says them."""
    keys = zone_keys(fleet, locale)
    return FleetView(
        robots=[
            RobotEntry(
                thing=robot.thing,
                name=spoken_in(robot, locale)[0],
                key=str(index + 1) if index < 9 else None,
                start=robot.start,
            )
            for index, robot in enumerate(fleet.robots)
        ],
        charge_below=fleet.battery_plan.charge_below,
        zones=[
            ZoneEntry(
                id=zone.id,
                name=zone_name_in(zone, locale),
                pose=zone.pose,
                radius=zone.radius,
                arm=zone.arm,
                key=keys.get(zone.id),
                area=zone.area,
            )
            for zone in fleet.zones
        ],
        floor=_drawn(fleet).layout(),
        experiment_thing=fleet.experiment_thing,
        map=picture.view if picture is not None else None,
    )


def _drawn(fleet: Fleet) -> Fleet:
    """The fleet with its map's size filled in (a map's floor; the page is told the map's
    file name, not where it lies on this computer), else as it is."""
    floor = load_floor(fleet)
    if floor is None:
        return fleet
    drawn = floor.drawn()
    name = PurePath(drawn.map or "").name
    return msgspec.structs.replace(fleet, floor=msgspec.structs.replace(drawn, map=name))


class Feed:
    """The station's view of the fleet, the conversation and the experiment."""

    def __init__(
        self, fleet: Fleet, *, clock: Callable[[], float] = now_ms, locale: str = SPOKEN_LOCALE
    ) -> None:
        self.fleet = fleet
        # The map's picture, made once: the station serves it (`MAP_PATH`).
        self.picture = floor_picture(fleet)
        self.view = fleet_view(fleet, locale, self.picture)
        self._clock = clock
        self._things = frozenset(fleet.robot_things)
        self._lock = threading.Lock()
        self._subscribers: list[Subscriber] = []
        self._robots: dict[str, RobotView] = {
            thing: RobotView(
                reported=None,
                version=None,
                online=None,
                last_seen=None,
                last_event=None,
                progress=None,
            )
            for thing in fleet.robot_things
        }
        self._conversation: deque[ConversationEntry] = deque(maxlen=CONVERSATION_LIMIT)
        self._commands: OrderedDict[str, CommandMessage] = OrderedDict()
        self._experiment: ExperimentStatus | None = None
        self._alerts: OrderedDict[str, AnnouncementMessage] = OrderedDict()
        self._announced: OrderedDict[str, None] = OrderedDict()
        self._tasks: TasksMessage | None = None
        self._trail: deque[AuditRecord] | None = None
        self.closed = False

    # -- pages ----------------------------------------------------------------------------

    def subscribe(self, limit: int = SUBSCRIBER_LIMIT) -> Subscriber:
        """A new page's queue, starting with a snapshot; nothing is missed in between."""
        subscriber = Subscriber(limit)
        with self._lock:
            subscriber.push(encode_page_message(self._snapshot()))
            if self.closed:
                subscriber.close()
            else:
                self._subscribers.append(subscriber)
        return subscriber

    def unsubscribe(self, subscriber: Subscriber) -> None:
        subscriber.close()
        with self._lock:
            if subscriber in self._subscribers:
                self._subscribers.remove(subscriber)

    @property
    def subscribers(self) -> int:
        with self._lock:
            return len(self._subscribers)

    def snapshot(self) -> Json:
        """What a new page starts from (`SnapshotMessage`), as JSON-ready builtins: a copy."""
        with self._lock:
            snapshot: Json = msgspec.to_builtins(self._snapshot())
            return snapshot

    def _snapshot(self) -> SnapshotMessage:
        """Call with the lock held, and encode before letting go of it: the robots and the
        commands in it are the feed's own, which change as messages come."""
        return SnapshotMessage(
            fleet=self.view,
            robots=self._robots,
            conversation=list(self._conversation),
            commands=self._commands,
            experiment=self._experiment,
            alerts=list(self._alerts.values()),
            server_time=self._clock(),
            tasks=self._tasks,
            trail=TrailMessage(records=list(self._trail)) if self._trail is not None else None,
        )

    def close(self) -> None:
        """End every page's stream (the server is stopping)."""
        with self._lock:
            self.closed = True
            subscribers, self._subscribers = self._subscribers, []
        for subscriber in subscribers:
            subscriber.close()

    def set_tasks(self, tasks: TasksMessage) -> None:
        """The fleet's task queue as just read: sent to the pages if it changed."""
        with self._lock:
            if tasks == self._tasks:
                return
            self._tasks = tasks
            self._broadcast(tasks, "tasks")

    def add_records(self, records: list[AuditRecord]) -> None:
        """Records of the audit trail just read (oldest first): the pages are sent the
        latest `TRAIL_SHOWN` when any is new (an empty list says the trail is there)."""
        with self._lock:
            first = self._trail is None
            if self._trail is None:
                self._trail = deque(maxlen=TRAIL_SHOWN)
            last = self._trail[-1].seq if self._trail else 0
            new = [record for record in records if record.seq > last]
            if not new and not first:
                return
            self._trail.extend(new)
            self._broadcast(TrailMessage(records=list(self._trail)), "trail")

    def _broadcast_change(self, change: RobotChange) -> None:
        """Send a robot's change to every page (merged with one not taken yet); call with
        the lock held."""
        closed = False
        for subscriber in self._subscribers:
            subscriber.push_change(change)
            closed = closed or subscriber.closed
        if closed:
            self._drop_overflowed()

    def _drop_overflowed(self) -> None:
        for subscriber in [s for s in self._subscribers if s.closed]:
            log.info("a station page fell too far behind; it will reconnect")
            self._subscribers.remove(subscriber)

    def _broadcast(self, message: PageMessage, key: str | None = None) -> None:
        """Send `message` to every page; call with the lock held, so order is kept."""
        encoded = encode_page_message(message)
        closed = False
        for subscriber in self._subscribers:
            subscriber.push(encoded, key)
            closed = closed or subscriber.closed
        if closed:
            self._drop_overflowed()

    # -- the broker's messages -------------------------------------------------------------

    def routes(self, *, turns: bool) -> list[tuple[str, Callable[[str, bytes], None]]]:
        """(filter, handler) pairs to subscribe; `turns` adds the local simulator's turns.
        Announcements come from the local announcer and from the cloud's announcer
        function alike, so they are always subscribed."""
        found: list[tuple[str, Callable[[str, bytes], None]]] = [
            (topics.ALL_SHADOW_DOCUMENTS, self.on_shadow_documents),
            (topics.ALL_PRESENCE, self.on_presence),
            (topics.ALL_EVENTS, self.on_event),
            (topics.ALL_ROBOT_CMDS, self.on_command),
            (topics.FLEET_CMD, self.on_command),
            (topics.EXPERIMENT_STATUS, self.on_experiment_status),
            (topics.ASSISTANT_ANNOUNCEMENTS, self.on_announcement),
        ]
        if turns:
            found.append((topics.ASSISTANT_TURNS, self.on_turn))
        return found

    def on_shadow_documents(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_shadow_topic(topic)
        if parsed is None or parsed[1] is not None or parsed[0] not in self._things:
            return  # named shadows and things outside the fleet are not drawn
        try:
            # Only `current` is decoded: `previous` is skipped unread, which matters with a
            # thousand robots reporting.
            current = _documents_decoder.decode(payload).current
        except msgspec.MsgspecError:
            log.warning("ignoring an unreadable shadow document on %s", topic)
            return
        self._shadow(parsed[0], current.state.reported or {}, current.version, self._clock())

    def load_shadow(self, thing: str, document: bytes) -> None:
        """A robot's shadow as read at start-up (GetThingShadow's body)."""
        try:
            body = json.loads(document)
            reported = body.get("state", {}).get("reported") or {}
            version = int(body.get("version", 0))
            stamps = _timestamps(body.get("metadata", {}).get("reported", {}))
        except (ValueError, TypeError, AttributeError):
            log.warning("ignoring an unreadable shadow document of %s", thing)
            return
        if isinstance(reported, dict) and thing in self._things:
            self._shadow(thing, reported, version, max(stamps) * 1000 if stamps else None)

    def _shadow(self, thing: str, reported: Json, version: int, seen: float | None) -> None:
        with self._lock:
            robot = self._robots[thing]
            if robot.version is not None and version <= robot.version:
                return  # an older document than one already shown (start-up read raced)
            changed, removed = reported_change(robot.reported, reported)
            change = RobotChange(thing=thing, version=version)
            if changed:
                change.reported = changed
            if removed:
                change.removed = removed
            robot.reported, robot.version = reported, version
            if seen is not None and seen > (robot.last_seen or 0):
                robot.last_seen = change.last_seen = seen
            if reported.get("status") != "navigating" and robot.progress is not None:
                robot.progress = change.progress = None
            self._acknowledged_by_shadow(thing, reported)
            self._broadcast_change(change)

    def on_presence(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        if parsed is None or parsed[0] not in self._things:
            return
        try:
            presence = decode_presence(payload)
        except ProtocolError as err:
            log.warning("ignoring presence on %s: %s", topic, err)
            return
        thing = parsed[0]
        with self._lock:
            robot = self._robots[thing]
            robot.online = presence.online
            if presence.online:
                robot.last_seen = max(robot.last_seen or 0, self._clock())
            self._broadcast_change(
                RobotChange(thing=thing, online=presence.online, last_seen=robot.last_seen)
            )

    def on_event(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        if parsed is None or parsed[0] not in self._things:
            return
        try:
            event = decode_event(payload)
        except ProtocolError as err:
            log.warning("ignoring an event on %s: %s", topic, err)
            return
        if event.thing != parsed[0]:
            return  # a robot speaking for another is not believed
        now = self._clock()
        with self._lock:
            robot = self._robots[event.thing]
            robot.last_seen = now
            robot.last_event = event
            if event.event == "progress":
                robot.progress = event
            elif event.event in DRIVE_ENDS:
                robot.progress = None
            if event.command_id is not None:
                self._acknowledged(event.command_id, event.thing, event.event, now)
            if event.event in EXCHANGE_EVENTS:
                # What a robot said, heard, understood: the conversation shows each one.
                fields = msgspec.structs.asdict(event)
                self._conversation.append(
                    EventMessage(**fields, last_seen=now, robots=[event.thing])
                )
                self._broadcast(EventMessage(**fields, last_seen=now))
                return
            # Anything else is the robot's state: its latest event and drive, coalesced with
            # the rest of its change (a fleet command's thousand answers are one message).
            change = RobotChange(thing=event.thing, last_seen=now)
            if event.event == "progress" or event.event in DRIVE_ENDS:
                change.progress = robot.progress
            if event.event != "progress":
                change.last_event = event
            self._broadcast_change(change)

    def on_command(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        if topic != topics.FLEET_CMD and (parsed is None or parsed[1] != "cmd"):
            return
        try:
            command = decode_command(payload)
        except ProtocolError:
            return  # the robot rejects it and says why; its event shows that
        target = parsed[0] if parsed is not None else "fleet"
        things = sorted(self._things) if target == "fleet" else [target]
        body = CommandMessage(
            id=command.id,
            target=target,
            robots=things,
            action=command.action,
            params=msgspec.convert(msgspec.to_builtins(command.params), CommandParams),
            source=command.source,
            seen=self._clock(),
            acks={},
        )
        with self._lock:
            if command.id in self._commands:
                return  # the same command twice (a retry) is one command
            self._commands[command.id] = body
            while len(self._commands) > COMMANDS_LIMIT:
                self._commands.popitem(last=False)
            # The assistant's commands are shown inside its turn; the others on their own.
            if command.source != "alexa":
                self._conversation.append(body)
            self._broadcast(body)

    def _acknowledged(self, command_id: str, thing: str, how: str, at: float) -> None:
        command = self._commands.get(command_id)
        if command is None or thing in command.acks:
            return
        # A fleet command's robots are the whole fleet: a set lookup, not a scan of a list
        # of thousands for each of their thousands of answers.
        if thing not in (self._things if command.target == "fleet" else command.robots):
            return
        latency = round(max(0.0, at - command.seen), 1)
        command.acks[thing] = Acknowledgment(how, latency)
        self._broadcast(AckMessage(id=command_id, thing=thing, event=how, latency_ms=latency))

    def _acknowledged_by_shadow(self, thing: str, reported: Json) -> None:
        last = reported.get("last_command")
        if isinstance(last, dict) and isinstance(last.get("id"), str):
            self._acknowledged(last["id"], thing, str(last.get("result")), self._clock())

    def on_turn(self, topic: str, payload: bytes) -> None:
        try:
            turn = decode_turn(payload)
        except ProtocolError as err:
            log.warning("ignoring a turn: %s", err)
            return
        self.add_turn(turn)

    def add_turn(self, turn: AssistantTurn | Mapping[str, Any]) -> None:
        """One exchange with the assistant: from the broker, or the station's own (the
        in-process simulator's turn message, validated here as a decoded one is)."""
        if not isinstance(turn, AssistantTurn):
            try:
                turn = turn_from_message(turn)
            except ProtocolError as err:
                log.warning("ignoring a turn: %s", err)
                return
        with self._lock:
            robots: set[str] = set()
            for command_id in turn.commands:
                seen = self._commands.get(command_id)
                if seen is not None:
                    robots.update(seen.robots)
            for slot in turn.slots.values():
                value = slot.get("id")
                if value in self._things:
                    robots.add(value)
                elif value == FLEET_GROUP:
                    robots.update(self._things)
            message = TurnMessage(**msgspec.structs.asdict(turn), robots=sorted(robots))
            self._conversation.append(message)
            self._broadcast(message)

    def on_announcement(self, topic: str, payload: bytes) -> None:
        try:
            announcement = decode_announcement(payload)
        except ProtocolError as err:
            log.warning("ignoring an announcement: %s", err)
            return
        self.add_announcement(announcement)

    def add_announcement(self, announcement: Announcement) -> None:
        """What the assistant said unprompted: into the conversation, and an alert until
        acknowledged. The same announcement twice (a redelivery) is shown once."""
        thing = announcement.thing
        with self._lock:
            if announcement.id in self._announced:
                return
            self._announced[announcement.id] = None
            while len(self._announced) > ANNOUNCEMENTS_REMEMBERED:
                self._announced.popitem(last=False)
            message = AnnouncementMessage(
                **msgspec.structs.asdict(announcement),
                robots=[thing] if thing in self._things else [],
            )
            self._conversation.append(message)
            self._alerts[announcement.id] = message
            while len(self._alerts) > ALERTS_LIMIT:
                self._alerts.popitem(last=False)
            self._broadcast(message)

    def acknowledge(self, announcement_id: str) -> list[str]:
        """Someone acknowledged the alert of `announcement_id`: it, and every other alert
        still open about the same robot and trouble, is no longer shown on any page.
        Returns the ids acknowledged (none if it was not, or no longer, an alert)."""
        with self._lock:
            alert = self._alerts.get(announcement_id)
            if alert is None:
                return []
            ids = [
                key
                for key, open_alert in self._alerts.items()
                if key == announcement_id
                or (
                    alert.thing is not None
                    and (open_alert.thing, open_alert.kind) == (alert.thing, alert.kind)
                )
            ]
            for key in ids:
                del self._alerts[key]
            self._broadcast(AlertAcknowledgedMessage(ids=ids))
            return ids

    def on_experiment_status(self, topic: str, payload: bytes) -> None:
        if not payload:
            self.set_experiment(None)  # the session ended (or its runner went away)
            return
        try:
            status = decode_experiment_status(payload)
        except ProtocolError as err:
            log.warning("ignoring the experiment status: %s", err)
            return
        self.set_experiment(status)

    def set_experiment(self, status: ExperimentStatus | None) -> None:
        with self._lock:
            self._experiment = status
            self._broadcast(ExperimentMessage(status=status))

    @property
    def experiment(self) -> Json | None:
        """The running session's status as JSON-ready builtins (what the desk reads), or None."""
        with self._lock:
            if self._experiment is None:
                return None
            status: Json = msgspec.to_builtins(self._experiment)
            return status


class _Reported(msgspec.Struct):
    reported: Json | None = None


class _Document(msgspec.Struct):
    state: _Reported
    version: int


class _Documents(msgspec.Struct):
    """The part of an `update/documents` message the station reads."""

    current: _Document


_documents_decoder = msgspec.json.Decoder(_Documents)


def _timestamps(metadata: object) -> list[float]:
    """Every `timestamp` leaf of a shadow's metadata (seconds since the epoch)."""
    if isinstance(metadata, dict):
        if isinstance(metadata.get("timestamp"), int | float) and len(metadata) == 1:
            return [float(metadata["timestamp"])]
        return [stamp for value in metadata.values() for stamp in _timestamps(value)]
    if isinstance(metadata, list):
        return [stamp for value in metadata for stamp in _timestamps(value)]
    return []
