"""The flags that say how a command reaches the broker, shared by `vahr experiment` and
`vahr station`: `--broker URL` and, for an mqtts:// broker, `--cert`, `--key` and `--ca`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from vahr.errors import VahrError

if TYPE_CHECKING:
    import argparse

    from vahr.protocol.broker import ClientCredentials


def add_broker_flags(
    parser: argparse.ArgumentParser, *, purpose: str, default: str | None = None
) -> None:
    """`--broker` (required when there is no `default`) and the mTLS credentials."""
    parser.add_argument(
        "--broker",
        required=default is None,
        default=default,
        help=f"MQTT broker {purpose}: mqtt://HOST:PORT, or mqtts://HOST:PORT with --cert, "
        "--key and --ca (AWS IoT Core, vahr up's mqtts)",
    )
    parser.add_argument("--cert", type=Path, help="client certificate for an mqtts:// broker")
    parser.add_argument("--key", type=Path, help="client private key for an mqtts:// broker")
    parser.add_argument("--ca", type=Path, help="CA certificate for an mqtts:// broker")


def client_credentials(args: argparse.Namespace) -> ClientCredentials | None:
    """The certificate, key and CA given, or None; one line if only some are."""
    if not (args.cert or args.key or args.ca):
        return None
    if not (args.cert and args.key and args.ca):
        raise VahrError("--cert, --key and --ca go together")
    from vahr.protocol.broker import ClientCredentials

    return ClientCredentials(cert_file=args.cert, key_file=args.key, ca_file=args.ca)
