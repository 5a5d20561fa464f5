"""The announcer's boto3 adapters: the skill's client credentials (Secrets Manager), the
policy's state (one DynamoDB item, written only if nobody wrote it meanwhile) and the
announcements topic (iot-data Publish, for the operator station). Library errors become
the announcer's errors here and nowhere else."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import boto3
import msgspec
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from announcer.errors import AnnouncerError, ConfigError, DeliveryFailed, StateConflict
from vahr.announce import PolicyState
from vahr.protocol import encode, topics

if TYPE_CHECKING:
    from vahr.protocol.announcements import Announcement

CLIENT_CONFIG = Config(
    connect_timeout=2.0, read_timeout=3.0, retries={"mode": "standard", "total_max_attempts": 3}
)
STATE_KEY = "policy"


class SkillCredentials:
    """The skill's Alexa Skill Messaging client id and secret, read once per cold start."""

    def __init__(self, secret: str, client: Any = None) -> None:
        self._secret = secret
        self._client = client or boto3.client("secretsmanager", config=CLIENT_CONFIG)
        self._cached: tuple[str, str] | None = None

    def __call__(self) -> tuple[str, str]:
        if self._cached is None:
            try:
                value = self._client.get_secret_value(SecretId=self._secret)["SecretString"]
                parsed = json.loads(value)
                self._cached = (str(parsed["clientId"]), str(parsed["clientSecret"]))
            except (ClientError, BotoCoreError) as err:
                raise ConfigError(f"cannot read the secret {self._secret}: {err}") from err
            except (ValueError, KeyError, TypeError) as err:
                raise ConfigError(
                    f"the secret {self._secret} must be JSON with clientId and clientSecret"
                ) from err
        return self._cached


class StateStore:
    """The policy's state as one item: `load` gives it with its version, `save` writes it
    only over that version (StateConflict otherwise)."""

    def __init__(self, table: str, client: Any = None) -> None:
        self._table = table
        self._client = client or boto3.client("dynamodb", config=CLIENT_CONFIG)

    def load(self) -> tuple[PolicyState, int]:
        try:
            item = self._client.get_item(
                TableName=self._table, Key={"id": {"S": STATE_KEY}}, ConsistentRead=True
            ).get("Item")
        except (ClientError, BotoCoreError) as err:
            raise AnnouncerError(f"cannot read the announcer's state: {err}") from err
        if item is None:
            return PolicyState(), 0
        try:
            state = msgspec.json.decode(item["state"]["S"], type=PolicyState)
        except (msgspec.DecodeError, KeyError) as err:
            raise AnnouncerError(f"the announcer's stored state is unreadable: {err}") from err
        return state, int(item["version"]["N"])

    def save(self, state: PolicyState, version: int) -> None:
        try:
            self._client.put_item(
                TableName=self._table,
                Item={
                    "id": {"S": STATE_KEY},
                    "version": {"N": str(version + 1)},
                    "state": {"S": msgspec.json.encode(state).decode()},
                },
                ConditionExpression="attribute_not_exists(id) OR version = :seen",
                ExpressionAttributeValues={":seen": {"N": str(version)}},
            )
        except ClientError as err:
            if err.response.get("Error", {}).get("Code") == "ConditionalCheckFailedException":
                raise StateConflict("the announcer's state changed meanwhile") from err
            raise AnnouncerError(f"cannot save the announcer's state: {err}") from err
        except BotoCoreError as err:
            raise AnnouncerError(f"cannot save the announcer's state: {err}") from err


class AnnouncementTopic:
    """Publishes each announcement on `vahr/assistant/announcements` (QoS 1), where an
    operator station hears it as it does on the local stack."""

    def __init__(self, endpoint: str | None, client: Any = None) -> None:
        self._client = client or boto3.client(
            "iot-data", endpoint_url=endpoint, config=CLIENT_CONFIG
        )

    def publish(self, announcement: Announcement) -> None:
        try:
            self._client.publish(
                topic=topics.ASSISTANT_ANNOUNCEMENTS, qos=1, payload=encode(announcement)
            )
        except (ClientError, BotoCoreError) as err:
            raise DeliveryFailed(
                f"cannot publish announcement {announcement.id} on "
                f"{topics.ASSISTANT_ANNOUNCEMENTS}: {err}"
            ) from err
