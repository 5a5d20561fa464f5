"""The local CA: made once, reused, and issuing certificates mosquitto and the SDK accept."""

from __future__ import annotations

import ssl
from typing import TYPE_CHECKING

from cryptography import x509
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

from vahr.pki import LocalCA

if TYPE_CHECKING:
    from pathlib import Path


def _cert(path: Path) -> x509.Certificate:
    return x509.load_pem_x509_certificate(path.read_bytes())


def test_the_ca_is_created_once_and_reused(tmp_path: Path) -> None:
    # Given a CA made in a state directory
    first = LocalCA.load_or_create(tmp_path)
    ca_pem = first.ca_file.read_bytes()
    server_pem = first.server_cert_file.read_bytes()
    # When it is loaded again
    second = LocalCA.load_or_create(tmp_path)
    # Then the same CA and server certificate are used
    assert second.ca_file.read_bytes() == ca_pem
    assert second.server_cert_file.read_bytes() == server_pem
    ca = _cert(second.ca_file)
    assert ca.extensions.get_extension_for_class(x509.BasicConstraints).value.ca is True


def test_the_server_certificate_names_localhost_and_the_loopback_address(tmp_path: Path) -> None:
    ca = LocalCA.load_or_create(tmp_path)
    server = _cert(ca.server_cert_file)
    san = server.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert san.get_values_for_type(x509.DNSName) == ["localhost"]
    assert [str(ip) for ip in san.get_values_for_type(x509.IPAddress)] == ["127.0.0.1"]
    eku = server.extensions.get_extension_for_class(x509.ExtendedKeyUsage).value
    assert list(eku) == [ExtendedKeyUsageOID.SERVER_AUTH]


def test_a_client_certificate_carries_the_thing_name_and_a_private_key(tmp_path: Path) -> None:
    ca = LocalCA.load_or_create(tmp_path / "state")
    # When a robot's credentials are issued
    creds = ca.issue_client("placebot1", tmp_path / "robot")
    # Then the certificate's CN is the thing name, for client authentication only
    cert = _cert(creds.cert_file)
    assert cert.subject.get_attributes_for_oid(NameOID.COMMON_NAME)[0].value == "placebot1"
    eku = cert.extensions.get_extension_for_class(x509.ExtendedKeyUsage).value
    assert list(eku) == [ExtendedKeyUsageOID.CLIENT_AUTH]
    # And the key is an unencrypted PKCS8 PEM readable by its owner only
    assert creds.key_file.read_text().startswith("-----BEGIN PRIVATE KEY-----")
    assert creds.key_file.stat().st_mode & 0o777 == 0o600
    assert (ca.directory / "ca.key").stat().st_mode & 0o777 == 0o600
    # And the chain verifies with the CA written beside it
    context = ssl.create_default_context(cafile=str(creds.ca_file))
    context.load_cert_chain(str(creds.cert_file), str(creds.key_file))
    assert creds.ca_file.read_bytes() == ca.ca_file.read_bytes()
    cert.verify_directly_issued_by(_cert(ca.ca_file))
