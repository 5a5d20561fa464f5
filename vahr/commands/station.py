"""`vahr station`: the operator station page against any VAHR deployment.

Against the local stack: `vahr station --broker mqtt://127.0.0.1:1883 --api
http://127.0.0.1:8180`. Against AWS IoT Core: `--broker mqtts://ENDPOINT:8883` with an
operator certificate (`--cert`, `--key`, `--ca`) and `--api https://ENDPOINT` (the iot-data
endpoint; docs/station.md). `vahr up` serves its own station already.
"""

from __future__ import annotations

import json
import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.cli_router import add_logging_flag, setup_logging
from vahr.commands.broker_flags import add_broker_flags, client_credentials
from vahr.commands.fleet_flag import add_fleet_flag, fleet_for

if TYPE_CHECKING:
    import argparse

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
    tls = client_credentials(args)
    deployment = Deployment(
        broker=args.broker,
        fleet=fleet_for(args.fleet, args.api),
        fleet_file=args.fleet,
        tls=tls,
        api=args.api,
    )
    config = StationConfig(
        port=args.port,
        host=args.host,
        token=args.token,
        voice=not args.no_voice,
        model_file=args.model,
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
            if station.server.token is not None:
                print(
                    f"  from another machine: http://<this machine's address>:{station.server.port}"
                    f"/?token={station.server.token}",
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
