"""The local stack without robots: broker, shadow service and data plane, started in order.

`LocalStack` is what `vahr up`, `vahr demo`, the tests and the benchmarks share: it makes
(or reuses) the local CA, writes the ACL, starts mosquitto with an mTLS listener (and, when
asked for, a plaintext one), connects the shadow service and the data plane to it with
their own identity, and serves the data-plane HTTP API. `stop()` undoes all of it.
"""

from __future__ import annotations

import json
import logging
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from vahr.local import identities
from vahr.local.acl import write_acl
from vahr.local.broker import BrokerConfig, Mosquitto, TlsListener
from vahr.local.dataplane import DataPlane, DataPlaneServer
from vahr.local.meter import Meter
from vahr.local.mqtt import MqttClient, MqttEndpoint
from vahr.local.ports import LOOPBACK, ensure_free
from vahr.local.recovery import StateLock, recover
from vahr.local.shadow_service import ShadowService
from vahr.local.shadow_store import ShadowStore
from vahr.pki import LocalCA
from vahr.protocol import ProtocolError, topics
from vahr.protocol.station import ORIGIN_PATTERN, Heard

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.local.alexa.simulator import AlexaSimulator, Turn

log = logging.getLogger(__name__)

# How long the broker keeps shadow requests for a shadow service that is away.
SHADOW_SESSION_EXPIRY_S = 24 * 3600


@dataclass(frozen=True, kw_only=True)
class StackConfig:
    state_dir: Path
    mqtts_port: int
    mqtt_port: int | None
    api_port: int
    # Names the data plane answers to besides the loopback ones (`vahr up --api-host`).
    api_hosts: frozenset[str] = frozenset()


class LocalStack:
    """AWS IoT Core's part of the system on 127.0.0.1. Use as a context manager."""

    def __init__(self, config: StackConfig) -> None:
        self.config = config
        self.meter = Meter()
        self.ca: LocalCA | None = None
        self.broker: Mosquitto | None = None
        self.store: ShadowStore | None = None
        self.shadows: ShadowService | None = None
        self.dataplane: DataPlane | None = None
        self._service_client: MqttClient | None = None
        self._server: DataPlaneServer | None = None
        self.alexa: AlexaSimulator | None = None
        self._claim = StateLock(config.state_dir)
        # One line saying what was put right after an earlier run's crash, or None.
        self.recovered: str | None = None

    @property
    def api_url(self) -> str:
        return f"http://{LOOPBACK}:{self.config.api_port}"

    @property
    def mqtts_url(self) -> str:
        return f"mqtts://{LOOPBACK}:{self.config.mqtts_port}"

    @property
    def mqtt_url(self) -> str | None:
        port = self.config.mqtt_port
        return f"mqtt://{LOOPBACK}:{port}" if port is not None else None

    def service_endpoint(self, identity: str = identities.TOOL) -> MqttEndpoint:
        """How a local service connects: the mTLS listener as `identity`, one of
        `vahr.local.identities.SERVICES` (each client its own: the broker makes the
        identity the client id)."""
        assert self.ca is not None, "start() first"
        if identity not in identities.SERVICES:
            raise ValueError(f"identity: {identity!r} is not one of the stack's services")
        return MqttEndpoint(
            port=self.config.mqtts_port, credentials=self.ca.service_credentials(identity)
        )

    @property
    def database(self) -> Path:
        return self.config.state_dir / "shadows.sqlite3"

    def start(self) -> LocalStack:
        cfg = self.config
        # The state directory first: a second run on it is refused before any port is
        # touched, and what a crashed run left (processes holding its ports, an unfinished
        # database journal) is cleared before anything needs it.
        unclean_pid = self._claim.acquire()
        try:
            self.recovered = recover(cfg.state_dir, unclean_pid=unclean_pid, database=self.database)
            if self.recovered:
                log.info("recovered %s: %s", cfg.state_dir, self.recovered)
            # Then every port, so a conflict is one clear line before anything starts.
            ensure_free(cfg.api_port, "data-plane API")
        except BaseException:
            self._claim.release()
            raise
        try:
            self.ca = LocalCA.load_or_create(cfg.state_dir)
            # Every identity the ACL names, issued once (a tool beside the stack, such as
            # `vahr station`, finds its certificate in STATE/pki/service/).
            for identity in identities.SERVICES:
                self.ca.service_credentials(identity)
            acl = write_acl(cfg.state_dir / "broker" / "acl")
            self.broker = Mosquitto(
                BrokerConfig(
                    state_dir=cfg.state_dir / "broker",
                    plain_port=cfg.mqtt_port,
                    tls=TlsListener(
                        port=cfg.mqtts_port,
                        ca_file=self.ca.ca_file,
                        cert_file=self.ca.server_cert_file,
                        key_file=self.ca.server_key_file,
                        acl_file=acl,
                    ),
                )
            )
            self.broker.start()
            # A persistent session: robots' shadow updates sent while this client is away
            # (a broker restart, a pause) are queued by the broker and applied when it is
            # back, as AWS's shadow service never misses one. With a clean session they
            # were dropped, and a robot that then stayed idle left its shadow stale.
            self._service_client = MqttClient(
                self.service_endpoint(identities.SHADOWS),
                client_id=identities.SHADOWS,
                session_expiry_s=SHADOW_SESSION_EXPIRY_S,
            )
            client = self._service_client
            self.store = ShadowStore(self.database)

            def publish_answer(topic: str, payload: bytes) -> None:
                # Answers go out without waiting for PUBACK: the paho network thread that
                # delivers requests must not block on its own acknowledgments.
                client.publish(topic, payload, qos=1, wait=False)

            self.shadows = ShadowService(self.store, publish_answer, self.meter)
            # Routes first: what a resumed session delivers at once finds its handler.
            self.shadows.attach(client)
            client.connect()

            def publish(topic: str, payload: bytes, qos: int, retain: bool) -> None:
                client.publish(topic, payload, qos=qos, retain=retain, wait=qos > 0)

            self.dataplane = DataPlane(self.shadows, publish, self.meter)
            self._server = DataPlaneServer(
                self.dataplane, cfg.api_port, hosts=cfg.api_hosts
            ).start()
        except BaseException:
            self.stop()
            raise
        return self

    def attach_alexa(
        self,
        *,
        ack_timeout_s: float | None = None,
        model_file: Path | None = None,
        fleet_file: Path | None = None,
        log_level: str = "WARNING",
        locale: str = "en-US",
    ) -> AlexaSimulator:
        """Serve the Alexa simulator (and the skill, in-process) at `POST /vahr/say`, in
        `locale`: its understanding data, and the locale of every request it sends."""
        from vahr.local.alexa.commands_seen import CommandLog
        from vahr.local.alexa.envelope import Identity
        from vahr.local.alexa.nlu import InteractionModel
        from vahr.local.alexa.simulator import AlexaSimulator
        from vahr.local.alexa.skill import load_skill_handler
        from vahr.local.alexa.understanding import load_understanding

        assert self.dataplane is not None, "start() first"
        log = CommandLog(starts_seen=True)
        self.dataplane.publish_starters.append(log.begin)
        self.dataplane.publish_observers.append(log.observe)
        # The classifier loads (or trains, when its cache is cold) while the rest starts;
        # the first utterance waits for it.
        understanding = load_understanding(locale)
        model = InteractionModel.load(model_file, background=True, understanding=understanding)
        # The skill serves one skill id, as on Lambda, and the simulated Echo's envelopes
        # carry it: the handler's check runs here too (skill.skill_gate).
        identity = Identity()
        handler = load_skill_handler(
            self.api_url,
            ack_timeout_s=ack_timeout_s,
            skill_id=identity.skill_id,
            fleet_file=str(fleet_file) if fleet_file else None,
            log_level=log_level,
        )
        service = self._service_client

        def publish_turn(turn: Turn) -> None:
            # Every exchange, whoever spoke, for the operator station's conversation.
            if service is not None:
                payload = json.dumps(turn.to_message(), separators=(",", ":")).encode()
                service.publish(topics.ASSISTANT_TURNS, payload, qos=1, wait=False)

        simulator = AlexaSimulator(
            model,
            handler,
            identity=identity,
            command_log=log.take,
            on_turn=publish_turn,
            locale=locale,
        )
        self.alexa = simulator

        def say(request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
            utterance = request.get("utterance")
            if request.get("end_session"):
                ended = simulator.end_session()
                return 200, ended.to_json() if ended else {"session_open": False}
            if not isinstance(utterance, str) or not utterance.strip():
                return 400, {"code": 400, "message": "utterance: a non-empty string is required"}
            asked = request.get("locale", locale)
            if asked != locale:
                message = (
                    f"locale: this system speaks {locale}; start it with vahr up --locale {asked}"
                )
                return 400, {"code": 400, "message": message}
            try:
                origin, heard = _speaker(request)
            except ProtocolError as err:
                return 400, {"code": 400, "message": str(err)}
            return 200, simulator.say(utterance, origin=origin, heard=heard).to_json()

        self.dataplane.local_routes[("POST", "/vahr/say")] = say
        return simulator

    def stop(self) -> None:
        """Stop what started, in reverse order; safe to call twice."""
        if self._server is not None:
            self._server.stop()
            self._server = None
        if self.shadows is not None:
            # Before the client: what it delivered so far is served and answered.
            self.shadows.stop()
        if self._service_client is not None:
            self._service_client.stop()
            self._service_client = None
        if self.store is not None:
            self.store.close()
            self.store = None
        if self.broker is not None:
            self.broker.stop()
            self.broker = None
        self._claim.release()

    def __enter__(self) -> LocalStack:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _speaker(request: dict[str, Any]) -> tuple[str, dict[str, Any] | None]:
    """Who spoke (`origin`, default "say") and what a recognizer heard, from a say request."""
    import msgspec

    origin = request.get("origin", "say")
    if not isinstance(origin, str) or not re.fullmatch(ORIGIN_PATTERN, origin):
        raise ProtocolError("origin", "must be a short lower-case word such as station-voice")
    heard = request.get("heard")
    if heard is None:
        return origin, None
    try:
        checked = msgspec.convert(heard, Heard)
    except msgspec.ValidationError as err:
        raise ProtocolError("heard", str(err)) from err
    return origin, msgspec.to_builtins(checked)
