"""The boto3 `iot-data` adapter of the RobotGateway port: the one wrapper of that client in
VAHR (the skill's, and the experiment's writer of its thing's shadow, use it alike).

The client is created once at cold start. It honours `AWS_ENDPOINT_URL_IOT_DATA_PLANE` like
any boto3 client, so the same code talks to AWS IoT Core, to moto, and to the local stack's
data-plane API. Timeouts are short because the whole answer must reach Alexa within 8 s.
Library errors become the skill's `GatewayError` family here and nowhere else.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError, NoCredentialsError, NoRegionError

from skill.errors import ConfigError, GatewayError, MissingCredentials, ShadowConflict

if TYPE_CHECKING:
    from skill.config import SkillConfig

# One retry at most: a second slow attempt would eat the acknowledgment budget.
CLIENT_CONFIG = Config(
    connect_timeout=1.0,
    read_timeout=1.5,
    retries={"mode": "standard", "total_max_attempts": 2},
    user_agent_extra="vahr-skill",
)


def create_client(config: SkillConfig) -> Any:
    """An iot-data client for the configured endpoint (boto3's default when unset)."""
    try:
        return boto3.client("iot-data", endpoint_url=config.data_endpoint, config=CLIENT_CONFIG)
    except NoRegionError:
        if config.data_endpoint is None:
            raise ConfigError(
                "no AWS region: set AWS_REGION or AWS_DEFAULT_REGION "
                "(or AWS_ENDPOINT_URL_IOT_DATA_PLANE for a local data plane)"
            ) from None
        # A local data plane ignores the region, but SigV4 signing needs one.
        return boto3.client(
            "iot-data",
            endpoint_url=config.data_endpoint,
            region_name=config.fallback_region,
            config=CLIENT_CONFIG,
        )


def client_for(endpoint_url: str | None, *, fallback_region: str = "us-east-1") -> Any:
    """An iot-data client for tools outside Lambda: boto3's region or `fallback_region`,
    and at a given endpoint without credentials, placeholder keys (a local data plane does
    not check signatures, but botocore will not send an unsigned request)."""
    session = boto3.session.Session()
    credentials: dict[str, str] = {}
    if endpoint_url is not None and session.get_credentials() is None:
        credentials = {"aws_access_key_id": "vahr-local", "aws_secret_access_key": "vahr-local"}
    return session.client(
        "iot-data",
        endpoint_url=endpoint_url,
        region_name=session.region_name or fallback_region,
        config=CLIENT_CONFIG,
        **credentials,
    )


class IotDataGateway:
    """RobotGateway over an iot-data client (thread-safe, as boto3 clients are)."""

    def __init__(self, client: Any) -> None:
        self._client = client

    @classmethod
    def from_config(cls, config: SkillConfig) -> IotDataGateway:
        return cls(create_client(config))

    def publish(self, topic: str, payload: bytes) -> None:
        try:
            self._client.publish(topic=topic, qos=1, payload=payload)
        except (ClientError, BotoCoreError) as err:
            raise _failure(f"publish to {topic}", err) from err

    def get_shadow(self, thing: str) -> bytes | None:
        try:
            response = self._client.get_thing_shadow(thingName=thing)
        except ClientError as err:
            if _code(err) == "ResourceNotFoundException":
                return None
            raise _failure(f"reading the shadow of {thing}", err) from err
        except BotoCoreError as err:
            raise _failure(f"reading the shadow of {thing}", err) from err
        body: bytes = response["payload"].read()
        return body

    def update_shadow(self, thing: str, payload: bytes) -> bytes:
        try:
            response = self._client.update_thing_shadow(thingName=thing, payload=payload)
        except ClientError as err:
            if _code(err) == "ConflictException":
                raise ShadowConflict(f"the shadow of {thing} changed meanwhile") from err
            raise _failure(f"updating the shadow of {thing}", err) from err
        except BotoCoreError as err:
            raise _failure(f"updating the shadow of {thing}", err) from err
        body: bytes = response["payload"].read()
        return body


def _code(err: ClientError) -> str:
    return str(err.response.get("Error", {}).get("Code", ""))


def _failure(what: str, err: ClientError | BotoCoreError) -> GatewayError:
    if isinstance(err, NoCredentialsError):
        return MissingCredentials(f"{what} failed: no AWS credentials")
    return GatewayError(f"{what} failed: {_describe(err)}")


def _describe(err: Exception) -> str:
    if isinstance(err, ClientError):
        message = err.response.get("Error", {}).get("Message") or ""
        return f"{_code(err)} {message}".strip()
    return str(err)
