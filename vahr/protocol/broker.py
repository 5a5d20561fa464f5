"""How a client reaches the broker: its address (one URL parser) and its mTLS identity
(one credentials type), for the robots' awscrt link and the lab's paho client alike.

`mqtt://HOST[:PORT]` is plaintext (port 1883 by default), allowed to robots only on
loopback (development); `mqtts://HOST[:PORT]` is mutual TLS (8883), as AWS IoT Core and
`vahr up`'s mqtts listener speak it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from urllib.parse import urlsplit

from vahr.errors import VahrError

LOOPBACK_HOSTS = frozenset({"127.0.0.1", "localhost", "::1"})
PLAINTEXT_PORT = 1883
TLS_PORT = 8883


@dataclass(frozen=True)
class ClientCredentials:
    """A client's certificate and key, and the CA that signed the broker's certificate
    (None: the system's trust store, e.g. for AWS IoT Core)."""

    cert_file: Path
    key_file: Path
    ca_file: Path | None = None

    def check_files(self) -> ClientCredentials:
        """Self, once each file exists; else a one-line error naming the missing one."""
        for label, path in (("cert", self.cert_file), ("key", self.key_file), ("ca", self.ca_file)):
            if path is not None and not Path(path).is_file():
                raise VahrError(f"--{label} {path}: no such file")
        return self


@dataclass(frozen=True)
class BrokerAddress:
    host: str
    port: int
    tls: bool


def parse_broker_url(url: str, *, name: str = "broker") -> BrokerAddress:
    """`mqtt://HOST[:PORT]` or `mqtts://HOST[:PORT]` -> where to connect, and whether mTLS."""
    address = _parse(url, name)
    if address is None:
        raise VahrError(f"{name} {url!r} is not an mqtt:// or mqtts://HOST:PORT URL")
    return address


def plaintext_loopback(url: str, *, name: str = "--broker") -> BrokerAddress:
    """A development broker: plaintext MQTT, and only on this machine's loopback."""
    address = _parse(url, name)
    if address is None or address.tls:
        raise VahrError(f"{name} {url!r}: expected mqtt://127.0.0.1:PORT")
    if address.host not in LOOPBACK_HOSTS:
        raise VahrError(
            f"{name} {url!r}: plaintext MQTT is allowed only to a loopback broker; "
            "use --endpoint with --cert, --key and --ca for any other host"
        )
    return address


def _parse(url: str, name: str) -> BrokerAddress | None:
    """The address, None for another scheme or no host; a malformed URL is an error."""
    try:
        parts = urlsplit(url)
        port = parts.port
    except ValueError as err:
        raise VahrError(f"{name} {url!r}: {err}") from err
    if parts.scheme not in ("mqtt", "mqtts") or not parts.hostname:
        return None
    tls = parts.scheme == "mqtts"
    return BrokerAddress(parts.hostname, port or (TLS_PORT if tls else PLAINTEXT_PORT), tls)
