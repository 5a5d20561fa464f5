"""The session's recorder over mTLS, as it connects to AWS IoT Core or `vahr up`'s mqtts."""

from __future__ import annotations

import datetime
import ipaddress
import threading
from typing import TYPE_CHECKING

import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

from vahr.errors import VahrError
from vahr.experiment.bus import Bus
from vahr.plumbing.ports import free_port
from vahr.protocol import encode, new_command, topics
from vahr.protocol.broker import ClientCredentials
from vahr.twin.broker import BrokerConfig, Mosquitto, TlsListener

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path


def _name(cn: str) -> x509.Name:
    return x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, cn)])


def _write(
    folder: Path, stem: str, key: ec.EllipticCurvePrivateKey, cert: x509.Certificate
) -> tuple[Path, Path]:
    key_file, cert_file = folder / f"{stem}.key", folder / f"{stem}.crt"
    key_file.write_bytes(
        key.private_bytes(
            serialization.Encoding.PEM,
            serialization.PrivateFormat.PKCS8,
            serialization.NoEncryption(),
        )
    )
    cert_file.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    return cert_file, key_file


def make_ca(folder: Path, name: str) -> tuple[ec.EllipticCurvePrivateKey, x509.Certificate, Path]:
    key = ec.generate_private_key(ec.SECP256R1())
    now = datetime.datetime.now(datetime.UTC)
    cert = (
        x509.CertificateBuilder()
        .subject_name(_name(name))
        .issuer_name(_name(name))
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=1))
        .not_valid_after(now + datetime.timedelta(days=1))
        .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
        .sign(key, hashes.SHA256())
    )
    ca_file, _ = _write(folder, name, key, cert)
    return key, cert, ca_file


def issue(
    folder: Path,
    ca: tuple[ec.EllipticCurvePrivateKey, x509.Certificate, Path],
    cn: str,
    *,
    server: bool,
) -> tuple[Path, Path]:
    ca_key, ca_cert, _ = ca
    key = ec.generate_private_key(ec.SECP256R1())
    now = datetime.datetime.now(datetime.UTC)
    builder = (
        x509.CertificateBuilder()
        .subject_name(_name(cn))
        .issuer_name(ca_cert.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=1))
        .not_valid_after(now + datetime.timedelta(days=1))
        .add_extension(
            x509.ExtendedKeyUsage(
                [ExtendedKeyUsageOID.SERVER_AUTH if server else ExtendedKeyUsageOID.CLIENT_AUTH]
            ),
            critical=False,
        )
    )
    if server:
        builder = builder.add_extension(
            x509.SubjectAlternativeName(
                [x509.DNSName("localhost"), x509.IPAddress(ipaddress.ip_address("127.0.0.1"))]
            ),
            critical=False,
        )
    return _write(folder, cn, key, builder.sign(ca_key, hashes.SHA256()))


@pytest.fixture
def tls_broker(tmp_path: Path) -> Iterator[tuple[Mosquitto, tuple, Path]]:
    ca = make_ca(tmp_path, "test-ca")
    server_cert, server_key = issue(tmp_path, ca, "broker", server=True)
    acl = tmp_path / "acl"
    acl.write_text("user vahr-experiment\ntopic readwrite #\n")
    port = free_port()
    broker = Mosquitto(
        BrokerConfig(
            state_dir=tmp_path / "broker",
            tls=TlsListener(
                port=port, ca_file=ca[2], cert_file=server_cert, key_file=server_key, acl_file=acl
            ),
        )
    )
    broker.start()
    try:
        yield broker, ca, tmp_path
    finally:
        broker.stop()


def test_the_recorder_works_over_mtls(tls_broker: tuple[Mosquitto, tuple, Path]) -> None:
    broker, ca, folder = tls_broker
    cert, key = issue(folder, ca, "vahr-experiment", server=False)
    received: list[str] = []
    seen = threading.Event()

    def on_message(topic: str, payload: bytes) -> None:
        received.append(topic)
        seen.set()

    # Given the recorder connected with a client certificate
    assert broker.config.tls is not None
    bus = Bus(
        f"mqtts://127.0.0.1:{broker.config.tls.port}",
        on_message,
        "vahr-experiment-t",
        tls=ClientCredentials(cert_file=cert, key_file=key, ca_file=ca[2]),
    )
    bus.start()
    try:
        # When the console publishes a command
        bus.publish(topics.robot_cmd("placebot1"), encode(new_command("ping", source="console")))
        # Then the recorder sees it on the wire
        assert seen.wait(5)
    finally:
        bus.stop()
    assert received == ["vahr/robots/placebot1/cmd"]


def test_a_broker_signed_by_another_ca_is_refused_in_one_line(
    tls_broker: tuple[Mosquitto, tuple, Path], tmp_path: Path
) -> None:
    broker, ca, folder = tls_broker
    cert, key = issue(folder, ca, "vahr-experiment", server=False)
    _, _, other_ca = make_ca(tmp_path, "other-ca")
    assert broker.config.tls is not None
    bus = Bus(
        f"mqtts://127.0.0.1:{broker.config.tls.port}",
        lambda t, p: None,
        "x",
        tls=ClientCredentials(cert_file=cert, key_file=key, ca_file=other_ca),
    )
    with pytest.raises(VahrError, match="TLS handshake with 127.0.0.1:.* failed"):
        bus.start()


def test_mqtts_needs_credentials() -> None:
    with pytest.raises(VahrError, match="needs --cert, --key and --ca"):
        Bus("mqtts://127.0.0.1:8883", lambda t, p: None, "x")
    with pytest.raises(VahrError, match="is not an mqtt:// or mqtts://"):
        Bus("http://127.0.0.1", lambda t, p: None, "x")
