"""The boto3 `iot-data` adapter that writes the experiment's state to its thing's shadow.

The state (weather, task I assignments, session id) goes into the reported state of the
classic shadow of `fleet.experiment_thing`, where the skill reads the weather from. boto3
honours `AWS_ENDPOINT_URL_IOT_DATA_PLANE`, so the same code talks to AWS IoT Core, to moto
and to the local data plane (`vahr up`'s `api` URL, passed as `endpoint_url`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError, NoCredentialsError, NoRegionError

from vahr.errors import VahrError
from vahr.protocol import ExperimentState, experiment_state_from_payload

if TYPE_CHECKING:
    from vahr.protocol import Fleet

_CONFIG = Config(
    connect_timeout=3, read_timeout=5, retries={"mode": "standard", "total_max_attempts": 3}
)
_FALLBACK_REGION = "us-east-1"


def _client(endpoint_url: str | None) -> Any:
    session = boto3.session.Session()
    region = session.region_name or _FALLBACK_REGION
    credentials: dict[str, str] = {}
    if endpoint_url is not None and session.get_credentials() is None:
        # A local data plane does not check signatures, but botocore will not send an
        # unsigned request: sign with placeholder keys rather than ask for real ones.
        credentials = {"aws_access_key_id": "vahr-local", "aws_secret_access_key": "vahr-local"}
    try:
        return session.client(
            "iot-data", endpoint_url=endpoint_url, region_name=region, config=_CONFIG, **credentials
        )
    except NoRegionError as err:  # pragma: no cover - region is always set above
        raise VahrError("no AWS region: set AWS_REGION") from err


class ExperimentShadow:
    """Read and write the experiment thing's reported state."""

    def __init__(self, fleet: Fleet, *, endpoint_url: str | None = None) -> None:
        self.thing = fleet.experiment_thing
        self._client = _client(endpoint_url)

    def write(self, state: ExperimentState) -> None:
        try:
            self._client.update_thing_shadow(thingName=self.thing, payload=state.to_payload())
        except NoCredentialsError as err:
            raise VahrError(
                f"cannot write the experiment state to the shadow of {self.thing}: no AWS "
                "credentials (give --api URL for the local stack, or --no-shadow)"
            ) from err
        except (ClientError, BotoCoreError) as err:
            raise VahrError(
                f"cannot write the experiment state to the shadow of {self.thing}: {err}"
            ) from err

    def read(self) -> ExperimentState | None:
        try:
            response = self._client.get_thing_shadow(thingName=self.thing)
        except ClientError as err:
            if err.response.get("Error", {}).get("Code") == "ResourceNotFoundException":
                return None
            raise VahrError(f"cannot read the shadow of {self.thing}: {err}") from err
        except (BotoCoreError, NoCredentialsError) as err:
            raise VahrError(f"cannot read the shadow of {self.thing}: {err}") from err
        return experiment_state_from_payload(response["payload"].read())
