"""The local certificate authority that stands in for AWS IoT's certificate registry.

Shared by the local stack (the broker's and the services' certificates) and by
`robot-agent provision --local` (a robot's), so it sits below both.

Created once per state directory with the `cryptography` package and reused across runs:
an EC P-256 CA, a server certificate for the broker (SAN `localhost` and `127.0.0.1`) and
client certificates whose common name is the thing name, which mosquitto's
`use_identity_as_username` turns into the username its ACL checks.
"""

from __future__ import annotations

import datetime as dt
import ipaddress
import os
from pathlib import Path

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

from vahr.errors import VahrError
from vahr.protocol.broker import ClientCredentials

CA_COMMON_NAME = "VAHR local CA"
SERVER_COMMON_NAME = "localhost"
SERVICE_COMMON_NAME = "vahr-service"
CA_VALIDITY = dt.timedelta(days=3650)
LEAF_VALIDITY = dt.timedelta(days=825)
# Certificates are backdated a little so a clock that is slightly behind still accepts them.
CLOCK_SKEW = dt.timedelta(minutes=5)


def _new_key() -> ec.EllipticCurvePrivateKey:
    return ec.generate_private_key(ec.SECP256R1())


def _write_key(key: ec.EllipticCurvePrivateKey, path: Path) -> None:
    pem = key.private_bytes(
        serialization.Encoding.PEM,
        serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption(),
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    # Create with 0600 from the start so the key is never readable by others, even briefly.
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "wb") as stream:
        stream.write(pem)
    path.chmod(0o600)


def _write_cert(cert: x509.Certificate, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(cert.public_bytes(serialization.Encoding.PEM))


def _name(common_name: str) -> x509.Name:
    return x509.Name(
        [
            x509.NameAttribute(NameOID.ORGANIZATION_NAME, "VAHR local"),
            x509.NameAttribute(NameOID.COMMON_NAME, common_name),
        ]
    )


def _subject_name(name: str) -> x509.GeneralName:
    """A SAN entry: an IP address as one, anything else as a DNS name."""
    try:
        return x509.IPAddress(ipaddress.ip_address(name))
    except ValueError:
        return x509.DNSName(name)


class LocalCA:
    """A CA kept in `state_dir/pki/`; `load_or_create` makes it on first use."""

    def __init__(self, directory: Path, key: ec.EllipticCurvePrivateKey, cert: x509.Certificate):
        self.directory = directory
        self._key = key
        self._cert = cert

    @property
    def ca_file(self) -> Path:
        return self.directory / "ca.crt"

    @property
    def server_cert_file(self) -> Path:
        return self.directory / "server.crt"

    @property
    def server_key_file(self) -> Path:
        return self.directory / "server.key"

    @classmethod
    def load_or_create(cls, state_dir: Path) -> LocalCA:
        """The CA of `state_dir` (with its server certificate), created on first use."""
        directory = Path(state_dir) / "pki"
        cert_file, key_file = directory / "ca.crt", directory / "ca.key"
        if cert_file.exists() and key_file.exists():
            try:
                cert = x509.load_pem_x509_certificate(cert_file.read_bytes())
                key = serialization.load_pem_private_key(key_file.read_bytes(), password=None)
            except (ValueError, TypeError) as err:
                raise VahrError(
                    f"the local CA in {directory} is unreadable ({err}); delete that folder "
                    "to make a new one (robots must then be provisioned again)"
                ) from err
            if not isinstance(key, ec.EllipticCurvePrivateKey):
                raise VahrError(f"the local CA key in {key_file} is not an EC key")
            ca = cls(directory, key, cert)
        else:
            ca = cls._create(directory)
        if not (ca.server_cert_file.exists() and ca.server_key_file.exists()):
            ca._issue(SERVER_COMMON_NAME, ca.server_cert_file, ca.server_key_file, server=True)
        return ca

    @classmethod
    def _create(cls, directory: Path) -> LocalCA:
        key = _new_key()
        now = dt.datetime.now(dt.UTC)
        cert = (
            x509.CertificateBuilder()
            .subject_name(_name(CA_COMMON_NAME))
            .issuer_name(_name(CA_COMMON_NAME))
            .public_key(key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - CLOCK_SKEW)
            .not_valid_after(now + CA_VALIDITY)
            .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
            .add_extension(
                x509.KeyUsage(
                    digital_signature=True,
                    content_commitment=False,
                    key_encipherment=False,
                    data_encipherment=False,
                    key_agreement=False,
                    key_cert_sign=True,
                    crl_sign=True,
                    encipher_only=False,
                    decipher_only=False,
                ),
                critical=True,
            )
            .add_extension(x509.SubjectKeyIdentifier.from_public_key(key.public_key()), False)
            .sign(key, hashes.SHA256())
        )
        _write_key(key, directory / "ca.key")
        _write_cert(cert, directory / "ca.crt")
        return cls(directory, key, cert)

    def issue_server(self, names: list[str], out_dir: Path) -> tuple[Path, Path]:
        """A server certificate for `names` (host names or IP addresses; the first is its
        common name) written to `out_dir` as `server.crt` and `server.key`: the operator
        station's HTTPS, for browsers that trust this CA."""
        if not names:
            raise VahrError("a server certificate needs at least one name")
        out_dir = Path(out_dir)
        cert_file, key_file = out_dir / "server.crt", out_dir / "server.key"
        self._issue(names[0], cert_file, key_file, server=True, names=names)
        return cert_file, key_file

    def _issue(
        self,
        common_name: str,
        cert_file: Path,
        key_file: Path,
        *,
        server: bool,
        names: list[str] | None = None,
    ) -> None:
        key = _new_key()
        now = dt.datetime.now(dt.UTC)
        builder = (
            x509.CertificateBuilder()
            .subject_name(_name(common_name))
            .issuer_name(self._cert.subject)
            .public_key(key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - CLOCK_SKEW)
            .not_valid_after(now + LEAF_VALIDITY)
            .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
            .add_extension(
                x509.AuthorityKeyIdentifier.from_issuer_public_key(self._key.public_key()), False
            )
        )
        if server:
            builder = builder.add_extension(
                x509.SubjectAlternativeName(
                    [_subject_name(name) for name in names or ["localhost", "127.0.0.1"]]
                ),
                critical=False,
            ).add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH]), False)
        else:
            builder = builder.add_extension(
                x509.ExtendedKeyUsage([ExtendedKeyUsageOID.CLIENT_AUTH]), False
            )
        cert = builder.sign(self._key, hashes.SHA256())
        _write_key(key, key_file)
        _write_cert(cert, cert_file)

    def issue_client(self, common_name: str, out_dir: Path) -> ClientCredentials:
        """A client certificate with CN = `common_name` (a thing name) written to `out_dir`.

        Writes `{cn}.cert.pem`, `{cn}.private.key` and `ca.crt`, replacing older ones.
        """
        if not common_name or "/" in common_name or common_name.startswith("."):
            raise VahrError(f"{common_name!r} is not a usable certificate common name")
        out_dir = Path(out_dir)
        cert_file = out_dir / f"{common_name}.cert.pem"
        key_file = out_dir / f"{common_name}.private.key"
        ca_file = out_dir / "ca.crt"
        self._issue(common_name, cert_file, key_file, server=False)
        if ca_file.resolve() != self.ca_file.resolve():
            _write_cert(self._cert, ca_file)
        return ClientCredentials(cert_file=cert_file, key_file=key_file, ca_file=ca_file)

    def service_credentials(self, name: str = SERVICE_COMMON_NAME) -> ClientCredentials:
        """A local service's identity (CN `name`, by default `vahr-service`), issued once
        and reused. The broker makes the common name the client id, so each service that
        holds a connection of its own has a name of its own."""
        out = self.directory / "service"
        existing = ClientCredentials(
            out / f"{name}.cert.pem",
            out / f"{name}.private.key",
            out / "ca.crt",
        )
        if all(
            p is not None and p.exists()
            for p in (existing.cert_file, existing.key_file, existing.ca_file)
        ):
            return existing
        return self.issue_client(name, out)
