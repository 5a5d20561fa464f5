"""`robot-agent provision`: make a robot's certificate, key, CA and config file."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from robot_agent.provisioning.files import Bundle, prepare_out_dir, write_config, write_private
from vahr.errors import VahrError
from vahr.protocol import identities

if TYPE_CHECKING:
    import argparse

DEFAULT_POLICY = "vahr-robot-policy"


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--thing", required=True, help="the robot's thing name")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--aws", action="store_true", help="register it in AWS IoT Core (boto3)")
    where.add_argument("--local", action="store_true", help="issue it from the local stack's CA")
    parser.add_argument("--out", help="where to write the files (default STATE_DIR/robots/THING)")
    parser.add_argument(
        "--state-dir", default=".state", help="local state directory (default .state)"
    )
    parser.add_argument(
        "--policy", default=DEFAULT_POLICY, help=f"IoT policy (default {DEFAULT_POLICY})"
    )
    parser.add_argument("--region", help="AWS region (default: the AWS configuration's)")
    parser.add_argument("--ca-file", help="CA certificate to use instead of Amazon Root CA 1")
    parser.add_argument(
        "--port", type=int, default=8883, help="MQTT port to write in the config (default 8883)"
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="replace credentials already in --out (with --aws, the replaced certificate is "
        "detached from the thing and deactivated)",
    )
    parser.add_argument("--json", action="store_true", help="print what was written as JSON")


def run(args: argparse.Namespace) -> int:
    try:
        identities.check_robot_thing(args.thing)
    except ValueError as err:
        raise VahrError(str(err)) from err
    if not 0 < args.port < 65536:
        raise VahrError(f"--port {args.port}: expected a TCP port (1-65535)")
    out_dir = Path(args.out) if args.out else Path(args.state_dir) / "robots" / args.thing
    names = ("cert.pem", "private.key") if args.aws else (f"{args.thing}.cert.pem",)
    prepare_out_dir(out_dir, names, force=args.force)
    bundle = _provision_aws(args, out_dir) if args.aws else _provision_local(args, out_dir)
    if args.json:
        print(json.dumps(bundle.to_json()))
    else:
        for label in ("cert", "key", "ca", "config"):
            value = getattr(bundle, label)
            print(f"{label + ':':8}{value if value is not None else '(none)'}")
        print(f"{'endpoint:':8}{bundle.endpoint}:{bundle.port}")
        if bundle.replaced:
            print(f"replaced: certificate {bundle.replaced} (detached and deactivated)")
        if bundle.note:
            print(f"note:   {bundle.note}")
    return 0


def _provision_aws(args: argparse.Namespace, out_dir: Path) -> Bundle:
    from robot_agent.provisioning.aws import (
        AMAZON_ROOT_CA_URL,
        amazon_root_ca,
        provision_thing,
        retire_certificate,
    )

    # Read before registering: a bad path must not leave an active certificate behind.
    ca_pem = _read_ca_file(args.ca_file) if args.ca_file else None
    # The certificate --force replaces: deactivated once the new one is written.
    old_cert = out_dir / "cert.pem"
    replaced_pem = old_cert.read_text() if args.force and old_cert.is_file() else None
    credentials = provision_thing(args.thing, policy=args.policy, region=args.region)
    cert = write_private(out_dir / "cert.pem", credentials.certificate_pem)
    key = write_private(out_dir / "private.key", credentials.private_key)
    note = None
    retired = None
    if replaced_pem is not None:
        retired = retire_certificate(args.thing, replaced_pem, region=args.region)
        if retired is None:
            note = (
                f"the certificate this replaced was not attached to {args.thing}; "
                "nothing was deactivated"
            )
    if ca_pem is not None:
        ca: Path | None = write_private(out_dir / "ca.pem", ca_pem)
    else:
        ca = amazon_root_ca(out_dir / "AmazonRootCA1.pem")
        if ca is None:
            note = f"download Amazon Root CA 1 from {AMAZON_ROOT_CA_URL} and pass it as --ca"
    config = write_config(
        out_dir,
        thing=args.thing,
        endpoint=credentials.endpoint,
        port=args.port,
        cert=cert,
        key=key,
        ca=ca,
    )
    return Bundle(args.thing, cert, key, ca, config, credentials.endpoint, args.port, note, retired)


def _read_ca_file(path: str) -> bytes:
    try:
        return Path(path).read_bytes()
    except OSError as err:
        raise VahrError(f"--ca-file {path}: {err.strerror or err}") from err


def _provision_local(args: argparse.Namespace, out_dir: Path) -> Bundle:
    try:
        from vahr.pki import LocalCA
    except ImportError as err:
        raise VahrError(f"--local needs the local stack (vahr.pki): {err}") from err
    try:
        issued = LocalCA.load_or_create(Path(args.state_dir)).issue_client(args.thing, out_dir)
    except OSError as err:
        raise VahrError(f"--state-dir {args.state_dir}: {err.strerror or err}") from err
    config = write_config(
        out_dir,
        thing=args.thing,
        endpoint="localhost",
        port=args.port,
        cert=issued.cert_file,
        key=issued.key_file,
        ca=issued.ca_file,
    )
    for path in (issued.cert_file, issued.key_file):
        path.chmod(0o600)
    return Bundle(
        args.thing,
        issued.cert_file,
        issued.key_file,
        issued.ca_file,
        config,
        "localhost",
        args.port,
    )
