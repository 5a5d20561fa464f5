"""`vahr station`: the operator station page against any VAHR deployment.

Against the local stack: `vahr station --broker mqtts://127.0.0.1:8883` with the stack's
service identity (`--cert`, `--key`, `--ca` from STATE/pki), or `--broker
mqtt://127.0.0.1:1883` when `vahr up --dev-plaintext` opened that listener, and `--api
http://127.0.0.1:8180`. Against AWS IoT Core: `--broker mqtts://ENDPOINT:8883` with the
station's certificate and `--api https://ENDPOINT` (the iot-data endpoint;
docs/station.md). `vahr up` serves its own station already, on loopback.

Off loopback (`--host`), serve it over HTTPS: `--tls` with a certificate from the local CA
of `--state-dir` (`--tls-name` for each name people use), `--tls-cert`/`--tls-key` with one
of your own, or `--public-origin` naming the HTTPS address of a reverse proxy in front.
"""

from __future__ import annotations

import json
import signal
import ssl
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.cli_router import add_logging_flag, setup_logging
from vahr.commands.broker_flags import add_broker_flags, client_credentials
from vahr.commands.fleet_flag import add_fleet_flag, fleet_for

if TYPE_CHECKING:
    import argparse

    from vahr.domain.people import People
    from vahr.station.server import ServerTls

DEFAULT_PORT = 8181


def configure(parser: argparse.ArgumentParser) -> None:
    add_broker_flags(parser, purpose="of the deployment (an operator's certificate on AWS)")
    parser.add_argument(
        "--api",
        help="the iot-data endpoint: vahr up's api URL, or https://ENDPOINT on AWS "
        "(shadows at start-up, and the assistant for push-to-talk)",
    )
    add_fleet_flag(parser, beside_a_stack=True)
    parser.add_argument(
        "--model", type=Path, help="interaction model (default: the one generated from the fleet)"
    )
    parser.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to serve the page on (default 127.0.0.1; elsewhere a token is required)",
    )
    parser.add_argument(
        "--port", type=int, default=DEFAULT_PORT, help=f"page port (default {DEFAULT_PORT})"
    )
    parser.add_argument("--token", help="the token to require (default: a new one, off loopback)")
    parser.add_argument(
        "--tls",
        action="store_true",
        help="serve HTTPS with a certificate from the local CA of --state-dir (trust its "
        "ca.crt on the tablets)",
    )
    parser.add_argument(
        "--tls-name",
        action="append",
        default=[],
        metavar="NAME",
        help="with --tls: a name or address people open the page by (repeat; localhost, "
        "127.0.0.1 and this machine's host name are always in)",
    )
    parser.add_argument("--tls-cert", type=Path, help="serve HTTPS with this certificate (PEM)")
    parser.add_argument("--tls-key", type=Path, help="the private key of --tls-cert (PEM)")
    parser.add_argument(
        "--public-origin",
        help="the address people open the page at behind a reverse proxy "
        "(https://station.lab.example): its requests are the page's own",
    )
    parser.add_argument(
        "--state-dir", type=Path, default=Path(".state"), help="where the local CA is (--tls)"
    )
    parser.add_argument(
        "--users",
        type=Path,
        metavar="FILE",
        help="the users file: each person signs in with their own token (token_sha256) and "
        "may do what their role allows (the skill in this process knows them too)",
    )
    parser.add_argument(
        "--audit-table",
        metavar="NAME",
        help="on AWS: the DynamoDB audit table the panel's orders are recorded in and the page "
        "shows (a local stack's --api has its own trail)",
    )
    parser.add_argument("--no-voice", action="store_true", help="no push-to-talk")
    parser.add_argument("--json", action="store_true", help="print the page's address as JSON")
    add_logging_flag(parser)
    parser.set_defaults(log_level="WARNING")


def run(args: argparse.Namespace) -> int:
    from vahr.errors import VahrError
    from vahr.station.assembly import StationConfig
    from vahr.station.deployment import Deployment, build_station

    setup_logging(args.log_level)
    if not 0 <= args.port <= 65535:
        raise VahrError(f"--port {args.port}: not a usable port")
    if args.token is not None and len(args.token) < 16:
        raise VahrError("--token must be at least 16 characters")
    if args.token is not None and args.users is not None:
        raise VahrError("give --token (one for everyone) or --users (one each), not both")
    served_tls = _served_tls(args)
    public_origin = _public_origin(args.public_origin)
    tls = client_credentials(args)
    deployment = Deployment(
        broker=args.broker,
        fleet=fleet_for(args.fleet, args.api),
        fleet_file=args.fleet,
        tls=tls,
        api=args.api,
        people=_people(args.users),
        users_file=args.users,
        audit_table=args.audit_table,
    )
    config = StationConfig(
        port=args.port,
        host=args.host,
        token=args.token,
        voice=not args.no_voice,
        model_file=args.model,
        tls=served_tls,
        public_origin=public_origin,
    )
    stopping = threading.Event()
    previous = {
        signum: signal.signal(signum, lambda *_: stopping.set())
        for signum in (signal.SIGINT, signal.SIGTERM)
    }
    station = build_station(config, deployment)
    try:
        station.start()
        if args.json:
            print(json.dumps({"station": station.url, "token": station.server.token}), flush=True)
        else:
            print(f"VAHR station: {station.url}   (Ctrl-C stops it)", flush=True)
            if station.server.token is not None and public_origin is None:
                print(
                    f"  from another machine: {station.server.scheme}://<this machine's address>:"
                    f"{station.server.port}/?token={station.server.token}",
                    flush=True,
                )
            if station.server.token is not None and not station.server.secure:
                print(
                    "vahr station: the page is plain HTTP off loopback: its token crosses the "
                    "network in the clear and browsers give it no microphone; use --tls, "
                    "--tls-cert or --public-origin",
                    file=sys.stderr,
                    flush=True,
                )
        stopping.wait()
    finally:
        station.stop()
        station.link.stop()
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    if not args.json:
        print("vahr station: stopped", file=sys.stderr)
    return 0


def _people(path: Path | None) -> People | None:
    if path is None:
        return None
    from vahr.domain.people import load_people
    from vahr.errors import VahrError
    from vahr.protocol import ProtocolError

    try:
        people = load_people(path)
    except ProtocolError as err:
        raise VahrError(f"--users {path}: {err}") from err
    if not any(person.token_sha256 for person in people.users):
        raise VahrError(
            f"--users {path}: nobody in it has a token_sha256, so nobody could sign in; "
            "make one with vahr users token"
        )
    return people


def _served_tls(args: argparse.Namespace) -> ServerTls | None:
    """The certificate the page is served with: --tls-cert's, one from the local CA, or none."""
    import socket

    from vahr.errors import VahrError
    from vahr.station.server import ServerTls

    if args.tls and (args.tls_cert or args.tls_key):
        raise VahrError("give --tls (the local CA) or --tls-cert and --tls-key, not both")
    if bool(args.tls_cert) != bool(args.tls_key):
        raise VahrError("--tls-cert and --tls-key go together")
    if args.tls_name and not args.tls:
        raise VahrError("--tls-name names the certificate --tls makes; add --tls")
    if args.tls_cert:
        served = ServerTls(args.tls_cert, args.tls_key)
    elif args.tls:
        from vahr.pki import LocalCA

        names = ["localhost", "127.0.0.1", socket.gethostname(), *args.tls_name]
        if args.host not in ("0.0.0.0", "::", ""):  # noqa: S104
            names.append(args.host)
        try:
            ca = LocalCA.load_or_create(args.state_dir)
            cert, key = ca.issue_server(list(dict.fromkeys(names)), ca.directory / "station")
        except OSError as err:
            raise VahrError(f"--state-dir {args.state_dir}: {err.strerror or err}") from err
        served = ServerTls(cert, key)
    else:
        return None
    try:
        served.context()
    except (OSError, ssl.SSLError) as err:
        raise VahrError(f"--tls-cert {served.cert_file}: cannot serve with it ({err})") from err
    return served


def _public_origin(origin: str | None) -> str | None:
    from urllib.parse import urlsplit

    from vahr.errors import VahrError

    if origin is None:
        return None
    parts = urlsplit(origin)
    if parts.scheme not in ("http", "https") or not parts.netloc or parts.path not in ("", "/"):
        raise VahrError(
            f"--public-origin {origin!r}: give the scheme, name and port only "
            "(https://station.lab.example)"
        )
    return f"{parts.scheme}://{parts.netloc}"
