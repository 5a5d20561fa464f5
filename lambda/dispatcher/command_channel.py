"""Commands to robots through iot-data Publish (QoS 1): the dispatcher's `Publish` port,
and the zones closed now, retained on `vahr/fleet/zones` (its `PublishClosures` port)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from dispatcher.errors import PublishError
from vahr.protocol import encode, topics

if TYPE_CHECKING:
    from vahr.protocol.messages import Command, ZoneClosures

CLIENT_CONFIG = Config(
    connect_timeout=2.0, read_timeout=3.0, retries={"mode": "standard", "total_max_attempts": 3}
)


class CommandChannel:
    """Publishes a command on `vahr/robots/{thing}/cmd`; a failure raises PublishError, so
    the dispatcher gives the task back to the queue."""

    def __init__(self, endpoint: str | None = None, client: Any = None) -> None:
        self._client = client or boto3.client(
            "iot-data", endpoint_url=endpoint, config=CLIENT_CONFIG
        )

    def __call__(self, thing: str, command: Command) -> None:
        topic = topics.robot_cmd(thing)
        try:
            self._client.publish(topic=topic, qos=1, payload=encode(command))
        except (ClientError, BotoCoreError) as err:
            raise PublishError(f"cannot publish command {command.id} to {topic}: {err}") from err

    def closures(self, closures: ZoneClosures) -> None:
        """Publish the zones closed now, retained (a robot that connects later reads it)."""
        topic = topics.FLEET_ZONES
        try:
            self._client.publish(topic=topic, qos=1, retain=True, payload=encode(closures))
        except (ClientError, BotoCoreError) as err:
            raise PublishError(f"cannot publish the closed zones to {topic}: {err}") from err
