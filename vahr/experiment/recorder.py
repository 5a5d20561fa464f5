"""Turn what is seen on the wire into log entries, and keep the world in step with it.

Transport-free: the MQTT adapter (`bus.Bus`) calls `on_message(topic, payload)`. Commands
(on robot and fleet command topics) and robot events are logged as they arrive, tagged with
the task in progress; each robot event is applied to the world and any change (an arm
loading or unloading, the LED) is logged right after it. Malformed messages are logged as
such rather than dropped, so the log shows everything the participant caused.

What the participant did on the operator station (`topics.EXPERIMENT_INPUT`: clicks, key
presses, push-to-talk, the observer's puzzle count) is logged too, as interactions and
observer input of this session, at the times the page measured moved onto this machine's
clock (`vahr.protocol.station_topics.on_clock`).
"""

from __future__ import annotations

import json
import logging
import threading
from typing import TYPE_CHECKING, Any

from vahr.experiment.eventlog import Kind, now
from vahr.protocol import ProtocolError, decode_command, decode_event, encode, topics
from vahr.protocol.station_topics import Interaction, decode_station_input, on_clock

logger = logging.getLogger(__name__)
# Interactions from the station are named apart from the observer's and the participant
# model's (`{task}-{n}`).
STATION_PREFIX = "station-"

if TYPE_CHECKING:
    from datetime import timedelta

    from vahr.experiment.eventlog import EventLog
    from vahr.experiment.world import World


class Recorder:
    """Logs the wire; `changed` is notified after every logged robot event."""

    def __init__(self, log: EventLog, world: World, *, session: str | None = None) -> None:
        self.log = log
        self.world = world
        # The session's name: station input for any other session is not this log's.
        self.session = session
        self.closed = False
        # How far each open interaction's page clock is from this one (set at its start).
        self._offsets: dict[str, timedelta] = {}
        self.task: str | None = None
        self.changed = threading.Condition()
        self._lock = threading.Lock()
        self._task_commands: set[str] = set()

    def on_message(self, topic: str, payload: bytes) -> None:
        if self.closed:
            return
        parsed = topics.parse_robot_topic(topic)
        if topic == topics.FLEET_CMD or (parsed is not None and parsed[1] == "cmd"):
            self._command(topic, payload, target=parsed[0] if parsed else "fleet")
        elif parsed is not None and parsed[1] == "events":
            self._event(topic, payload)
        elif topic == topics.EXPERIMENT_INPUT:
            self._station_input(payload)

    def _command(self, topic: str, payload: bytes, *, target: str) -> None:
        try:
            command = decode_command(payload)
        except ProtocolError as err:
            self.log.append(
                Kind.COMMAND,
                {
                    "topic": topic,
                    "target": target,
                    "malformed": str(err),
                    "payload": payload.decode("utf-8", "replace")[:512],
                },
                task=self.task,
            )
            return
        body: dict[str, Any] = json.loads(encode(command))
        body.update(topic=topic, target=target)
        with self._lock:
            self.log.append(Kind.COMMAND, body, task=self.task)
            self._task_commands.add(command.id)

    def _event(self, topic: str, payload: bytes) -> None:
        try:
            event = decode_event(payload)
        except ProtocolError as err:
            self.log.append(
                Kind.ROBOT_EVENT, {"topic": topic, "malformed": str(err)}, task=self.task
            )
            return
        body: dict[str, Any] = json.loads(encode(event))
        with self._lock:  # world changes must follow their event in the log
            self.log.append(Kind.ROBOT_EVENT, body, task=self.task)
            command_id = body.get("command_id")
            for_task = command_id is None or command_id in self._task_commands
            for change in self.world.apply(body, for_task=for_task):
                self.log.append(Kind.WORLD, change, task=self.task)
        with self.changed:
            self.changed.notify_all()

    def _station_input(self, payload: bytes) -> None:
        received = now()
        try:
            message = decode_station_input(payload)
        except ProtocolError as err:
            logger.warning("ignoring station input: %s", err)
            return
        if self.session is None or message.session != self.session:
            return  # another session's, or a station left open from an earlier one
        # The page measured the interaction on its own clock: its start and end move by the
        # same amount, so its length is the page's (whatever the network did in between).
        offset = on_clock(message.at, message.sent, received) - message.at
        if isinstance(message, Interaction):
            if message.phase == "started":
                self._offsets[message.id] = offset
            else:
                offset = self._offsets.pop(message.id, offset)
        at = message.at + offset
        with self._lock:
            if not isinstance(message, Interaction):
                body = {"what": "puzzle_piece", "count": message.count, "source": "station"}
                self.log.append(Kind.OBSERVER, body, task=self.task, at=at)
                return
            data: dict[str, Any] = {
                "id": STATION_PREFIX + message.id,
                "channel": message.channel,
                "text": message.text,
                "source": "station",
            }
            if message.phase == "started":
                self.log.append(Kind.INTERACTION_STARTED, data, task=self.task, at=at)
                return
            data["commands"] = list(message.commands)
            if not message.counts:
                data["counts"] = False
            if message.asks:
                data["asks"] = True
            for name in ("speech", "intent", "error"):
                value = getattr(message, name)
                if value is not None:
                    data[name] = value
            self.log.append(Kind.INTERACTION_ENDED, data, task=self.task, at=at)

    def close(self) -> None:
        """Log nothing more (the session is about to end)."""
        with self._lock:
            self.closed = True

    def set_task(self, task: str | None, commands: set[str] | None = None) -> None:
        """Tag what follows with `task`; `commands` are its commands already logged (resume)."""
        with self._lock:
            self.task = task
            self._task_commands = set(commands or ())

    def end_task(self, task: str, reason: str) -> None:
        """Log the end of `task` after any robot event being logged, with its world changes.

        The runner decides a task from the logged robot events; without the lock, the LED
        change caused by the deciding delivery could land after `task_ended`, outside the task.
        """
        with self._lock:
            self.world.disarm_led()
            self.log.append(Kind.TASK_ENDED, {"task": task, "reason": reason}, task=task)
            self.task = None
            self._task_commands = set()

    def log_world(self, changes: list[dict[str, Any]]) -> None:
        with self._lock:
            for change in changes:
                self.log.append(Kind.WORLD, change, task=self.task)
