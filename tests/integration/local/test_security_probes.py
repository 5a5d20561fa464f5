"""Security probes on the local stack, as an attacker holding one robot's certificate (or
none) would try them. Each probe is refused where AWS IoT Core refuses it, and afterwards
the broker and the data plane still serve everyone else. What mosquitto does differently
from AWS is stated in docs/reliability.md, and asserted here as it is.

Negative TLS probes use `ssl` and paho rather than the AWS SDK, whose failed handshakes
surface only after 10-18 s (as measured against mosquitto 2.0.11 on loopback).
"""

from __future__ import annotations

import datetime as dt
import socket
import ssl
import threading
import urllib.request
from typing import TYPE_CHECKING, Any

import paho.mqtt.client as paho
import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion
from paho.mqtt.packettypes import PacketTypes
from paho.mqtt.properties import Properties

from vahr.pki import LocalCA
from vahr.plumbing.mqtt import MqttClient
from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.pki import ClientCredentials
    from vahr.twin.stack import LocalStack

NOT_AUTHORIZED = 0x87


class Probe:
    """A paho MQTT 5 client over mTLS that records what it receives and its PUBACKs."""

    def __init__(
        self,
        port: int,
        credentials: ClientCredentials,
        client_id: str,
        *,
        session_expiry_s: int = 0,
    ) -> None:
        self.client = paho.Client(
            CallbackAPIVersion.VERSION2, client_id=client_id, protocol=MQTTProtocolVersion.MQTTv5
        )
        self.client.tls_set_context(_context(credentials))
        self.received: list[tuple[str, bytes]] = []
        self.acks: dict[int, int] = {}
        self.disconnects: list[str] = []
        self._changed = threading.Condition()
        connected = threading.Event()
        self.client.on_connect = lambda *a: connected.set()
        self.client.on_message = self._on_message
        self.client.on_publish = self._on_publish
        self.client.on_subscribe = lambda *a: self._notify()
        self.client.on_disconnect = lambda c, u, f, rc, p: self._disconnected(str(rc))
        properties = Properties(PacketTypes.CONNECT)
        properties.SessionExpiryInterval = session_expiry_s
        self.client.connect(
            "127.0.0.1",
            port,
            keepalive=30,
            clean_start=session_expiry_s == 0,
            properties=properties,
        )
        self.client.loop_start()
        assert connected.wait(10), "probe could not connect"

    def _notify(self) -> None:
        with self._changed:
            self._changed.notify_all()

    def _disconnected(self, reason: str) -> None:
        with self._changed:
            self.disconnects.append(reason)
            self._changed.notify_all()

    def _on_message(self, client: Any, userdata: Any, message: paho.MQTTMessage) -> None:
        with self._changed:
            self.received.append((message.topic, bytes(message.payload)))
            self._changed.notify_all()

    def _on_publish(self, client: Any, userdata: Any, mid: int, reason: Any, props: Any) -> None:
        with self._changed:
            self.acks[mid] = int(reason.value)
            self._changed.notify_all()

    def publish(self, topic: str, payload: bytes = b"{}") -> int:
        """Publish QoS 1 and return the PUBACK reason code."""
        info = self.client.publish(topic, payload, qos=1)
        with self._changed:
            assert self._changed.wait_for(lambda: info.mid in self.acks, 10), topic
            return self.acks[info.mid]

    def subscribe(self, topic_filter: str) -> None:
        done = threading.Event()
        self.client.on_subscribe = lambda *a: done.set()
        self.client.subscribe(topic_filter, qos=1)
        assert done.wait(10)

    def received_until(self, marker: bytes, timeout_s: float = 10.0) -> list[str]:
        """The topics received (retained ones too) up to the message carrying `marker`."""
        with self._changed:
            assert self._changed.wait_for(
                lambda: any(payload == marker for _, payload in self.received), timeout_s
            ), marker
            topics_seen = []
            for topic, payload in self.received:
                topics_seen.append(topic)
                if payload == marker:
                    return topics_seen
        raise AssertionError("unreachable")

    def close(self) -> None:
        self.client.disconnect()
        self.client.loop_stop()


def _context(credentials: ClientCredentials) -> ssl.SSLContext:
    context = ssl.create_default_context(cafile=str(credentials.ca_file))
    context.load_cert_chain(str(credentials.cert_file), str(credentials.key_file))
    return context


@pytest.fixture
def intruder(local_stack: LocalStack, tmp_path: Path) -> Iterator[Probe]:
    """placebot2's genuine certificate, in an attacker's hands."""
    assert local_stack.ca is not None
    credentials = local_stack.ca.issue_client("placebot2", tmp_path / "placebot2")
    probe = Probe(local_stack.config.mqtts_port, credentials, "placebot2")
    yield probe
    probe.close()


# Everything placebot2 must not publish: another robot's command, events, presence, shadow
# requests and room speech (its peers' rights), the fleet command (the operator's right),
# and the shadow service's answers, even on its own shadow (the service's right: a forged
# delta would carry a command).
FORBIDDEN_PUBLISH = [
    topics.robot_cmd("placebot1"),
    topics.robot_events("placebot1"),
    topics.robot_presence("placebot1"),
    topics.shadow("placebot1", "update"),
    topics.shadow("placebot1", "get"),
    topics.shadow("placebot1", "delete"),
    topics.shadow("placebot1", "update", "arm"),
    topics.room_robot_speech("placebot1"),
    topics.FLEET_CMD,
    topics.robot_cmd("placebot2"),
    topics.shadow("placebot1", "update/delta"),
    topics.shadow("placebot2", "update/delta"),
    topics.shadow("placebot2", "update/accepted"),
    topics.shadow("placebot2", "get/accepted"),
    "vahr/anything/else",
]


def test_a_robot_certificate_is_refused_every_other_identitys_topics(
    local_stack: LocalStack, intruder: Probe
) -> None:
    with MqttClient(local_stack.service_endpoint()) as watcher:
        seen: list[str] = []
        markers = threading.Semaphore(0)

        def record(topic: str, payload: bytes) -> None:
            seen.append(topic)
            if topic == topics.robot_events("placebot2"):
                markers.release()

        watcher.subscribe("#", record)
        watcher.subscribe("$aws/#", record)
        # Given a first event of placebot2's own: what the watcher saw before it (retained
        # messages of earlier tests) is not this test's business
        assert intruder.publish(topics.robot_events("placebot2")) == 0
        assert markers.acquire(timeout=10)
        before = len(seen)
        # When placebot2's certificate publishes where only others may
        codes = {topic: intruder.publish(topic) for topic in FORBIDDEN_PUBLISH}
        # Then every publish is refused (MQTT 5 PUBACK 0x87, Not authorized)...
        assert codes == dict.fromkeys(FORBIDDEN_PUBLISH, NOT_AUTHORIZED)
        # ...while its own rights still work, and the refused messages never reached
        # anyone: the broker keeps one publisher's order, so its own event comes next.
        assert intruder.publish(topics.robot_events("placebot2")) == 0
        assert markers.acquire(timeout=10)
        assert seen[before:] == [topics.robot_events("placebot2")]
        assert intruder.disconnects == []


def test_a_robot_certificate_hears_nothing_of_another_robot(
    local_stack: LocalStack, intruder: Probe
) -> None:
    # Given placebot2 subscribes to placebot1's command topic and whole shadow (mosquitto
    # grants such a subscription and filters each message; AWS refuses it in the SUBACK)
    intruder.subscribe(topics.robot_cmd("placebot1"))
    intruder.subscribe(topics.shadow_filter("placebot1"))
    intruder.subscribe(topics.robot_events("placebot1"))
    # When the service sends placebot1 a command and a shadow answer, then an event
    # placebot2 may read
    with MqttClient(local_stack.service_endpoint()) as service:
        service.publish(topics.robot_cmd("placebot1"), b'{"secret":1}')
        service.publish(topics.shadow("placebot1", "update/delta"), b'{"secret":2}')
        service.publish(topics.robot_events("placebot1"), b'{"event":"marker-1"}')
    # Then of all it received (retained events of earlier tests included), nothing was
    # placebot1's command or shadow, up to the event that came after both secrets
    received = intruder.received_until(b'{"event":"marker-1"}')
    assert set(received) == {topics.robot_events("placebot1")}


def _handshake(port: int, context: ssl.SSLContext) -> str | None:
    """None if mosquitto accepts the TLS client, else the error the client saw."""
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=10) as raw:
            with context.wrap_socket(raw, server_hostname="localhost") as tls:
                # TLS 1.2 (the listener's setting): a refused client certificate fails
                # the handshake itself. A CONNECT then proves the session is usable.
                tls.sendall(b"\x10\x10\x00\x04MQTT\x05\x02\x00\x1e\x00\x00\x03abc")
                answer = tls.recv(4)
                return None if answer[:1] == b"\x20" else f"no CONNACK: {answer!r}"
    except (ssl.SSLError, OSError) as err:
        return type(err).__name__


def _certificate(
    ca: LocalCA, common_name: str, out: Path, *, not_after: dt.datetime
) -> ClientCredentials:
    """A client certificate of `ca` with a chosen expiry (the CA's own issuing code
    always makes valid ones)."""
    credentials = ca.issue_client(common_name, out)
    key = ec.generate_private_key(ec.SECP256R1())
    ca_key = serialization.load_pem_private_key((ca.directory / "ca.key").read_bytes(), None)
    ca_cert = x509.load_pem_x509_certificate(ca.ca_file.read_bytes())
    assert isinstance(ca_key, ec.EllipticCurvePrivateKey)
    cert = (
        x509.CertificateBuilder()
        .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, common_name)]))
        .issuer_name(ca_cert.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(not_after - dt.timedelta(days=30))
        .not_valid_after(not_after)
        .add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.CLIENT_AUTH]), False)
        .sign(ca_key, hashes.SHA256())
    )
    credentials.cert_file.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    credentials.key_file.write_bytes(
        key.private_bytes(
            serialization.Encoding.PEM,
            serialization.PrivateFormat.PKCS8,
            serialization.NoEncryption(),
        )
    )
    return credentials


def test_expired_foreign_and_missing_certificates_are_refused_at_the_handshake(
    local_stack: LocalStack, tmp_path: Path
) -> None:
    assert local_stack.ca is not None
    port = local_stack.config.mqtts_port
    now = dt.datetime.now(dt.UTC)
    genuine = local_stack.ca.issue_client("placebot1", tmp_path / "genuine")
    expired = _certificate(
        local_stack.ca, "placebot1", tmp_path / "expired", not_after=now - dt.timedelta(days=1)
    )
    foreign = LocalCA.load_or_create(tmp_path / "elsewhere").issue_client(
        "placebot1", tmp_path / "foreign"
    )
    no_certificate = ssl.create_default_context(cafile=str(genuine.ca_file))
    trusting = _context(foreign)
    trusting.load_verify_locations(str(genuine.ca_file))  # it trusts our server; we not it
    # Then only the genuine, valid certificate gets a session
    assert _handshake(port, _context(genuine)) is None
    assert _handshake(port, _context(expired)) is not None
    assert _handshake(port, trusting) is not None
    assert _handshake(port, no_certificate) is not None


def test_a_certificate_claiming_another_robots_client_id_cannot_take_its_session(
    local_stack: LocalStack, tmp_path: Path
) -> None:
    # AWS refuses such a CONNECT (its policy binds iot:Connect to client/<thing name>).
    # mosquitto 2.0.11 makes the certificate's name the client id whatever id is claimed
    # (use_username_as_clientid): the impostor is connected as itself, and the robot it
    # claims to be keeps its session, its connection and its queued commands.
    assert local_stack.ca is not None
    port = local_stack.config.mqtts_port
    own = local_stack.ca.issue_client("placebot2", tmp_path / "placebot2")
    stolen = local_stack.ca.issue_client("placebot1", tmp_path / "placebot1")
    # Given placebot2 with a persistent session, away while a command is queued for it
    robot = Probe(port, own, "placebot2", session_expiry_s=600)
    robot.subscribe(topics.robot_cmd("placebot2"))
    robot.close()
    with MqttClient(local_stack.service_endpoint()) as service:
        service.publish(topics.robot_cmd("placebot2"), b'{"queued":1}')
    # When placebot1's certificate connects claiming placebot2's client id and session
    impostor = Probe(port, stolen, "placebot2", session_expiry_s=600)
    try:
        impostor.subscribe(topics.robot_cmd("placebot2"))
        impostor.subscribe(topics.robot_events("placebot1"))
        # Then placebot2 comes back to its own session: the queued command is delivered
        robot = Probe(port, own, "placebot2", session_expiry_s=600)
        try:
            robot.received_until(b'{"queued":1}')
            # And the impostor's connection does not push placebot2 off, nor the other way
            # round: they are two clients, placebot1 and placebot2
            with MqttClient(local_stack.service_endpoint()) as service:
                service.publish(topics.robot_cmd("placebot2"), b'{"live":2}')
                service.publish(topics.robot_events("placebot1"), b'{"event":"marker-2"}')
            assert robot.received_until(b'{"live":2}')
            received = impostor.received_until(b'{"event":"marker-2"}')
            assert set(received) == {topics.robot_events("placebot1")}
            assert robot.disconnects == []
            assert impostor.disconnects == []
            # Its publishes are judged by its certificate, not by the id it claimed
            assert impostor.publish(topics.robot_events("placebot2")) == NOT_AUTHORIZED
        finally:
            robot.close()
    finally:
        impostor.close()


def test_oversized_and_deeply_nested_payloads_leave_the_services_serving(
    local_stack: LocalStack, intruder: Probe
) -> None:
    shadow = local_stack.store
    assert shadow is not None
    rejected: list[bytes] = []
    got = threading.Event()
    with MqttClient(local_stack.service_endpoint()) as watcher:
        watcher.subscribe(
            topics.shadow("placebot2", "update/rejected"),
            lambda _t, p: (rejected.append(p), got.set()),
        )
        # When the robot sends a 1 MB event and a shadow update nested 4,000 deep
        # (mosquitto takes it: its limit is not AWS's 128 KB; PUBACK 0x10 = no subscriber)
        assert intruder.publish(topics.robot_events("placebot2"), b"x" * 1_000_000) < 0x80
        deep = b"[" * 4000 + b"]" * 4000
        intruder.publish(
            topics.shadow("placebot2", "update"), b'{"state":{"reported":{"a":' + deep + b"}}}"
        )
        # Then the shadow service refuses the update as AWS would (400), and still serves
        assert got.wait(10)
        assert b'"code":400' in rejected[0]
        assert (
            intruder.publish(
                topics.shadow("placebot2", "update"), b'{"state":{"reported":{"zone":"B"}}}'
            )
            == 0
        )
    assert _wait(lambda: _reported_zone(local_stack) == "B")


def _reported_zone(stack: LocalStack) -> str | None:
    assert stack.store is not None
    try:
        zone: str | None = stack.store.get("placebot2")["state"]["reported"].get("zone")
    except Exception:  # noqa: BLE001 - not stored yet
        return None
    return zone


def _wait(condition: Any, timeout_s: float = 10.0) -> bool:
    from tests.support.fault_injection_steps import wait_until

    wait_until(condition, timeout_s)
    return True


def test_a_flood_of_connections_does_not_stop_the_broker_or_the_api(
    local_stack: LocalStack, tmp_path: Path
) -> None:
    # Given 300 sockets held open on the broker (half never start TLS, half send garbage)
    # and 100 idle connections to the data plane
    port, api = local_stack.config.mqtts_port, local_stack.config.api_port
    held: list[socket.socket] = []
    try:
        for index in range(300):
            sock = socket.create_connection(("127.0.0.1", port), timeout=10)
            if index % 2:
                sock.sendall(b"\x16\x03\x01\x00\x05garbage")
            held.append(sock)
        held += [socket.create_connection(("127.0.0.1", api), timeout=10) for _ in range(100)]
        # Then a genuine robot still connects, publishes and is heard
        assert local_stack.ca is not None
        credentials = local_stack.ca.issue_client("placebot1", tmp_path / "placebot1")
        robot = Probe(port, credentials, "placebot1")
        try:
            robot.subscribe(topics.robot_events("placebot2"))
            with MqttClient(local_stack.service_endpoint()) as service:
                service.publish(topics.robot_events("placebot2"), b'{"event":"marker-3"}')
            robot.received_until(b'{"event":"marker-3"}')
        finally:
            robot.close()
        # And the data plane answers
        with urllib.request.urlopen(f"{local_stack.api_url}/vahr/health", timeout=10) as answer:
            assert answer.status == 200
    finally:
        for sock in held:
            sock.close()
