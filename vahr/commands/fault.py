"""`vahr fault THING stuck|fail|offline|clear`: inject a fault into a running simulated robot.

For demos, rehearsals and tests of what the assistant announces. It asks the running
system's data plane (`POST /vahr/fault`), which passes the fault to the robot on its
development fault topic and reports the robot's answer; a robot not in the fleet, one that
is not simulated, or one that does not answer is a one-line error.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from vahr.protocol.fault_request import DEFAULT_OFFLINE_S, FAULT_KINDS

if TYPE_CHECKING:
    import argparse

DONE = {
    "stuck": "{thing} is stuck: it stops where it is on its current or next way",
    "fail": "{thing} will fail: its current or next goal aborts",
    "offline": "{thing} went offline: it comes back in {offline_s:g} s",
    "clear": "{thing}: injected faults not yet applied are cleared",
}


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("thing", help="the robot's thing name, e.g. placebot1")
    parser.add_argument("fault", choices=FAULT_KINDS, help="what happens to it")
    parser.add_argument("--api", help="the running system's API (default $VAHR_API or :8180)")
    parser.add_argument(
        "--offline-s",
        type=float,
        default=DEFAULT_OFFLINE_S,
        help=f"how long an offline robot stays away, wall seconds (default {DEFAULT_OFFLINE_S:g})",
    )
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")


def run(args: argparse.Namespace) -> int:
    from vahr.errors import VahrError
    from vahr.plumbing.client import call, default_api

    if not 0 < args.offline_s <= 3600:
        raise VahrError("--offline-s must be in (0, 3600]")
    body = {"thing": args.thing, "fault": args.fault, "offline_s": args.offline_s}
    answer = call(args.api or default_api(), "POST", "/vahr/fault", body)
    if args.json:
        print(json.dumps(answer))
    else:
        print(DONE[args.fault].format(thing=args.thing, offline_s=args.offline_s))
    return 0
