"""Lost tasks and robots gone to charge, told to the announcer function: Lambda Invoke,
asynchronously.

A task the dispatcher could not see through (its robot was sent elsewhere by name, went
offline, or never acknowledged its command) is told as `{"lost_task": LostTask}`, and a
robot it sent to charge by itself as `{"gone_to_charge": GoneToCharge}`
(`vahr.protocol.lost_tasks`); the announcer says them as it says a robot's trouble. The
invocation is asynchronous (`Event`): Lambda queues it, retries it twice and then keeps it
in the announcer's dead-letter queue, so the dispatcher neither waits for Alexa nor loses
the news when the announcer fails. A refused invocation raises `AnnounceError`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
import msgspec
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from dispatcher.errors import AnnounceError
from vahr.protocol.lost_tasks import GONE_TO_CHARGE_KEY, LOST_TASK_KEY, GoneToCharge, LostTask

if TYPE_CHECKING:
    from datetime import datetime

    from vahr.dispatch import Task
    from vahr.protocol.lost_tasks import LostWhy, Tidings

CLIENT_CONFIG = Config(
    connect_timeout=2.0, read_timeout=3.0, retries={"mode": "standard", "total_max_attempts": 3}
)


def lost_task(task: Task, why: LostWhy, at: datetime) -> LostTask:
    """What the announcer is told of `task`, held by its robot until now."""
    return LostTask(
        task=task.id, thing=task.thing or "", kind=task.kind, zone=task.zone, at=at, why=why
    )


def gone_to_charge(task: Task, at: datetime) -> GoneToCharge:
    """What the announcer is told of `task`, a charge the dispatcher gave by itself."""
    return GoneToCharge(thing=task.thing or "", zone=task.zone, at=at)


class AnnouncerChannel:
    """Invokes the announcer function (by name or ARN) with each lost task and each robot
    gone to charge."""

    def __init__(self, function: str, client: Any = None) -> None:
        self.function = function
        self._client = client or boto3.client("lambda", config=CLIENT_CONFIG)

    def __call__(self, tidings: Tidings) -> None:
        payload: dict[str, Tidings]
        if isinstance(tidings, LostTask):
            payload, what = {LOST_TASK_KEY: tidings}, f"task {tidings.task} is lost"
        else:
            payload, what = {GONE_TO_CHARGE_KEY: tidings}, f"{tidings.thing} went to charge"
        try:
            self._client.invoke(
                FunctionName=self.function,
                InvocationType="Event",
                Payload=msgspec.json.encode(payload),
            )
        except (ClientError, BotoCoreError) as err:
            raise AnnounceError(
                f"cannot tell the announcer {self.function} that {what}: {err}"
            ) from err
