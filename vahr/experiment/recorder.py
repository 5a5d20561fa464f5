"""Turn what is seen on the wire into log entries, and keep the world in step with it.

Transport-free: the MQTT adapter (`bus.Bus`) calls `on_message(topic, payload)`. Commands
(on robot and fleet command topics) and robot events are logged as they arrive, tagged with
the task in progress; each robot event is applied to the world and any change (an arm
loading or unloading, the LED) is logged right after it. Malformed messages are logged as
such rather than dropped, so the log shows everything the participant caused.
"""

from __future__ import annotations

import json
import threading
from typing import TYPE_CHECKING, Any

from vahr.experiment.eventlog import Kind
from vahr.protocol import ProtocolError, decode_command, decode_event, encode, topics

if TYPE_CHECKING:
    from vahr.experiment.eventlog import EventLog
    from vahr.experiment.world import World


class Recorder:
    """Logs the wire; `changed` is notified after every logged robot event."""

    def __init__(self, log: EventLog, world: World) -> None:
        self.log = log
        self.world = world
        self.task: str | None = None
        self.changed = threading.Condition()
        self._lock = threading.Lock()
        self._task_commands: set[str] = set()

    def on_message(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        if topic == topics.FLEET_CMD or (parsed is not None and parsed[1] == "cmd"):
            self._command(topic, payload, target=parsed[0] if parsed else "fleet")
        elif parsed is not None and parsed[1] == "events":
            self._event(topic, payload)

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
