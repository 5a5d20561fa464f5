"""A station against any VAHR deployment: the local stack (`vahr up`) or AWS IoT Core.

It connects to the deployment's broker as an operator (client id `vahr-station-...`; on AWS
with a certificate under the operator policy) and reads each robot's shadow once through
the iot-data endpoint (`--api`). The assistant depends on what `--api` is:

- a local stack (it answers `GET /vahr/health`): its Alexa simulator, over `POST /vahr/say`;
  every turn, whoever spoke, arrives on `topics.ASSISTANT_TURNS`;
- AWS's iot-data endpoint: an Alexa simulator in this process in front of the real skill
  handler, configured for that endpoint (the AWS credentials of the environment need the
  skill's iot-data rights, docs/station.md). Alexa itself publishes no turns, so the
  conversation holds the station's own turns and the robots' exchanges.

`vahr up`'s own station runs in the stack's process instead: `on_local_system`, which
`vahr.local.system.LocalSystem` calls with its broker client, its simulator as the
assistant and its shadow store (the local stack does not import the station).
"""

from __future__ import annotations

import dataclasses
import json
import logging
import urllib.error
import urllib.request
import uuid
from dataclasses import dataclass
from typing import TYPE_CHECKING

from vahr.assistant import SimulatorAssistant
from vahr.errors import VahrError
from vahr.plumbing.client import HttpAssistant
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.protocol import topics
from vahr.protocol.broker import parse_broker_url
from vahr.protocol.identities import STATION_CLIENT_PREFIX
from vahr.station.assembly import Station, StationConfig
from vahr.station.feed import Feed
from vahr.station.trail_feed import HttpTrail

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.domain.people import People
    from vahr.plumbing.client import Assistant
    from vahr.protocol.broker import ClientCredentials
    from vahr.station.trail_feed import StationTrail

log = logging.getLogger(__name__)

CLIENT_ID_PREFIX = STATION_CLIENT_PREFIX
HEALTH_TIMEOUT_S = 3.0


@dataclass(frozen=True, kw_only=True)
class Deployment:
    broker: str
    fleet: Fleet
    # The file `fleet` came from, for the skill run in this process (None: the bundled one).
    fleet_file: Path | None = None
    tls: ClientCredentials | None = None
    api: str | None = None
    ack_timeout_s: float | None = None
    # Who may do what (`vahr station --users`): people sign in; None, anyone may do all.
    people: People | None = None
    users_file: Path | None = None
    # The audit trail on AWS (`vahr station --audit-table`); a local stack's is its own.
    audit_table: str | None = None


def is_local_stack(api: str) -> bool:
    """Whether `api` is a local stack's data plane (which also serves `/vahr/health`)."""
    try:
        with urllib.request.urlopen(
            f"{api.rstrip('/')}/vahr/health", timeout=HEALTH_TIMEOUT_S
        ) as r:
            return bool(json.loads(r.read()).get("ok"))
    except (urllib.error.URLError, TimeoutError, OSError, ValueError, AttributeError):
        return False


def build_station(config: StationConfig, deployment: Deployment) -> Station:
    """Connect to the deployment and build its station (not started)."""
    address = parse_broker_url(deployment.broker)
    if address.tls and deployment.tls is None:
        raise VahrError(f"broker {deployment.broker} needs --cert, --key and --ca for mTLS")
    link = MqttClient(
        MqttEndpoint(
            host=address.host,
            port=address.port,
            credentials=deployment.tls if address.tls else None,
        ),
        client_id=f"{CLIENT_ID_PREFIX}{uuid.uuid4().hex[:12]}",
    )
    feed = Feed(deployment.fleet)
    api = deployment.api
    local = api is not None and is_local_stack(api)
    assistant: Assistant | None = None
    trail: StationTrail | None = None
    if api is not None and local:
        assistant = HttpAssistant(api)
        trail = HttpTrail(api)
        if config.tasks_url is None:
            # The local stack's dispatcher serves the fleet's task queue beside its data plane.
            config = dataclasses.replace(config, tasks_url=f"{api.rstrip('/')}/vahr/tasks")
    elif api is not None:
        assistant = _simulator_for(api, config.model_file, deployment, feed, link)
    if deployment.audit_table is not None:
        from skill.audit_table import AuditTable

        trail = AuditTable(deployment.audit_table)
    link.connect()
    try:
        return Station(
            config,
            deployment.fleet,
            link=link,
            assistant=assistant,
            read_shadow=_shadow_reader(api) if api is not None else None,
            turns=local,
            feed=feed,
            people=deployment.people,
            trail=trail,
        )
    except BaseException:
        link.stop()
        raise


def on_local_system(
    *,
    port: int,
    fleet: Fleet,
    link: MqttClient,
    assistant: Assistant,
    read_shadow: Callable[[str], bytes | None],
    tasks_url: str | None = None,
    locale: str = "en-US",
    people: People | None = None,
    trail: StationTrail | None = None,
    model_file: Path | None = None,
) -> Station:
    """`vahr up`'s station, started: on the stack's broker, the simulator in-process, shadows
    read from the store, every turn seen on the broker, the task queue from `tasks_url`, its
    words and names in the stack's `locale`, `people` signing in, the stack's audit trail,
    and push-to-talk listening for the English interaction model in `model_file` (None:
    generated from the fleet)."""
    return Station(
        StationConfig(port=port, tasks_url=tasks_url, locale=locale, model_file=model_file),
        fleet,
        link=link,
        assistant=assistant,
        read_shadow=read_shadow,
        people=people,
        trail=trail,
    ).start()


def _simulator_for(
    api: str, model_file: Path | None, deployment: Deployment, feed: Feed, link: MqttClient
) -> Assistant:
    """The Alexa simulator and the real skill in this process, for AWS's iot-data endpoint."""
    from vahr.assistant import (
        AlexaSimulator,
        CommandLog,
        Identity,
        InteractionModel,
        load_skill_handler,
    )

    commands = CommandLog()
    # The skill publishes through iot-data; its commands are seen coming back from the broker.
    for topic_filter in (topics.ALL_ROBOT_CMDS, topics.FLEET_CMD):
        link.subscribe(topic_filter, commands.observe)
    if model_file is None:
        from vahr.skill_model.generator import build_interaction_model

        # The names of the fleet the station follows, whichever file it came from.
        model = InteractionModel(build_interaction_model(deployment.fleet))
    else:
        model = InteractionModel.load(model_file)
    fleet_file = str(deployment.fleet_file) if deployment.fleet_file else None
    # The skill in this process serves its simulated Echo's skill id, as on Lambda.
    identity = Identity()
    handler = load_skill_handler(
        api,
        ack_timeout_s=deployment.ack_timeout_s,
        fleet_file=fleet_file,
        skill_id=identity.skill_id,
        users_file=str(deployment.users_file) if deployment.users_file else None,
        audit_table=deployment.audit_table,
    )
    simulator = AlexaSimulator(
        model,
        handler,
        identity=identity,
        command_log=commands.take,
        on_turn=lambda turn: feed.add_turn(turn.to_message()),
    )
    return SimulatorAssistant(simulator)


def _shadow_reader(api: str) -> Callable[[str], bytes | None]:
    from skill.errors import GatewayError, MissingCredentials
    from skill.iot_data import IotDataGateway, client_for

    gateway = IotDataGateway(client_for(api))

    def read(thing: str) -> bytes | None:
        try:
            return gateway.get_shadow(thing)
        except MissingCredentials as err:
            raise VahrError(f"cannot read the shadow of {thing}: no AWS credentials") from err
        except GatewayError as err:
            log.warning("cannot read the shadow of %s: %s", thing, err)
            return None

    return read
