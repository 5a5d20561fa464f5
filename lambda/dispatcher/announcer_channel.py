"""Lost tasks told to the announcer function: Lambda Invoke, asynchronously.

A task the dispatcher could not see through (its robot was sent elsewhere by name, went
offline, or never acknowledged its command) is told as `{"lost_task": LostTask}`
(`vahr.protocol.lost_tasks`), and the announcer says it as it says a robot's trouble. The
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
from vahr.protocol.lost_tasks import LOST_TASK_KEY, LostTask

if TYPE_CHECKING:
    from datetime import datetime

    from vahr.dispatch import Task
    from vahr.protocol.lost_tasks import LostWhy

CLIENT_CONFIG = Config(
    connect_timeout=2.0, read_timeout=3.0, retries={"mode": "standard", "total_max_attempts": 3}
)


def lost_task(task: Task, why: LostWhy, at: datetime) -> LostTask:
    """What the announcer is told of `task`, held by its robot until now."""
    return LostTask(
        task=task.id, thing=task.thing or "", kind=task.kind, zone=task.zone, at=at, why=why
    )


class AnnouncerChannel:
    """Invokes the announcer function (by name or ARN) with each lost task."""

    def __init__(self, function: str, client: Any = None) -> None:
        self.function = function
        self._client = client or boto3.client("lambda", config=CLIENT_CONFIG)

    def __call__(self, lost: LostTask) -> None:
        try:
            self._client.invoke(
                FunctionName=self.function,
                InvocationType="Event",
                Payload=msgspec.json.encode({LOST_TASK_KEY: lost}),
            )
        except (ClientError, BotoCoreError) as err:
            raise AnnounceError(
                f"cannot tell the announcer {self.function} that task {lost.task} is lost: {err}"
            ) from err
