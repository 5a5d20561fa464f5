"""The local stack without robots: broker, shadow service, data plane and audit trail,
started in order.

`LocalStack` is what `vahr up`, `vahr demo`, the tests and the benchmarks share: it makes
(or reuses) the local CA, writes the ACL, starts mosquitto with an mTLS listener (and, when
asked for, a plaintext one), connects the shadow service and the data plane to it with
their own identity, and serves the data-plane HTTP API. `stop()` undoes all of it.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING

from vahr.pki import LocalCA
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.plumbing.ports import LOOPBACK, ensure_free
from vahr.twin import identities
from vahr.twin.acl import write_acl
from vahr.twin.broker import BrokerConfig, Mosquitto, TlsListener
from vahr.twin.dataplane import DataPlane, DataPlaneServer
from vahr.twin.meter import Meter
from vahr.twin.recovery import StateLock, recover
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore
from vahr.twin.trail_store import AUDIT_PATH, SqliteTrail, TrailApi

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path


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

    def __init__(
        self, config: StackConfig, *, awaiting: Callable[[], list[str]] | None = None
    ) -> None:
        """`awaiting` says what the system built on this stack still waits for before it
        can take a command (`GET /vahr/health` answers 503 until nothing)."""
        self.config = config
        self._awaiting = awaiting
        self.meter = Meter()
        self.ca: LocalCA | None = None
        self.broker: Mosquitto | None = None
        self.store: ShadowStore | None = None
        self.shadows: ShadowService | None = None
        self.dataplane: DataPlane | None = None
        # The audit trail (the twin of the DynamoDB audit table), served at /vahr/audit.
        self.trail: SqliteTrail | None = None
        self._service_client: MqttClient | None = None
        self._server: DataPlaneServer | None = None
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
        `vahr.twin.identities.SERVICES` (each client its own: the broker makes the
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
            self.dataplane.awaiting = self._awaiting
            self.trail = SqliteTrail.in_state_dir(cfg.state_dir)
            trail_api = TrailApi(self.trail)
            self.dataplane.local_routes[("POST", AUDIT_PATH)] = trail_api.append
            self.dataplane.local_routes[("GET", AUDIT_PATH)] = trail_api.page
            self._server = DataPlaneServer(
                self.dataplane, cfg.api_port, hosts=cfg.api_hosts
            ).start()
        except BaseException:
            self.stop()
            raise
        return self

    def publish_service(self, topic: str, payload: bytes) -> None:
        """Publish as the local services (QoS 1, without waiting for the acknowledgment):
        what the hosts on this stack tell the station, such as the assistant's turns."""
        if self._service_client is not None:
            self._service_client.publish(topic, payload, qos=1, wait=False)

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
        if self.trail is not None:
            self.trail.close()
            self.trail = None
        if self.broker is not None:
            self.broker.stop()
            self.broker = None
        self._claim.release()

    def __enter__(self) -> LocalStack:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
