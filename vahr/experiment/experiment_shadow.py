"""The experiment thing's shadow: where the session's state is written and read.

The state (weather, task I assignments, session id) goes into the reported state of the
classic shadow of `fleet.experiment_thing`, where the skill reads the weather from. The
calls go through the skill's own iot-data adapter (`skill.iot_data`, the one wrapper of
boto3's iot-data client), so the same code talks to AWS IoT Core, to moto and to the local
data plane (`vahr up`'s `api` URL, passed as `endpoint_url`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill.errors import GatewayError, MissingCredentials
from skill.iot_data import IotDataGateway, client_for
from vahr.errors import VahrError
from vahr.protocol import ExperimentState, experiment_state_from_payload

if TYPE_CHECKING:
    from vahr.domain import Fleet


class ExperimentShadow:
    """Read and write the experiment thing's reported state."""

    def __init__(self, fleet: Fleet, *, endpoint_url: str | None = None) -> None:
        self.thing = fleet.experiment_thing
        self._gateway = IotDataGateway(client_for(endpoint_url))

    def write(self, state: ExperimentState) -> None:
        try:
            self._gateway.update_shadow(self.thing, state.to_payload())
        except MissingCredentials as err:
            raise VahrError(
                f"cannot write the experiment state to the shadow of {self.thing}: no AWS "
                "credentials (give --api URL for the local stack, or --no-shadow)"
            ) from err
        except GatewayError as err:
            raise VahrError(
                f"cannot write the experiment state to the shadow of {self.thing}: {err}"
            ) from err

    def read(self) -> ExperimentState | None:
        try:
            payload = self._gateway.get_shadow(self.thing)
        except GatewayError as err:
            raise VahrError(f"cannot read the shadow of {self.thing}: {err}") from err
        return experiment_state_from_payload(payload) if payload is not None else None
