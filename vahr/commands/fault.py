"""`vahr fault THING stuck|fail|offline|clear|battery [PERCENT]`: inject a fault into a
running simulated robot (`battery PERCENT` sets its charge).

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
    "battery": "{thing}'s battery is at {percent:g} %",
}


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("thing", help="the robot's thing name, e.g. placebot1")
    parser.add_argument("fault", choices=FAULT_KINDS, help="what happens to it")
    parser.add_argument("percent", nargs="?", help="battery only: the charge to set, 0 to 100")
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
    body: dict[str, object] = {
        "thing": args.thing,
        "fault": args.fault,
        "offline_s": args.offline_s,
    }
    percent = _percent(args.fault, args.percent)
    if percent is not None:
        body["percent"] = percent
    answer = call(args.api or default_api(), "POST", "/vahr/fault", body)
    if args.json:
        print(json.dumps(answer))
    else:
        print(DONE[args.fault].format(thing=args.thing, offline_s=args.offline_s, percent=percent))
    return 0


def _percent(fault: str, given: str | None) -> float | None:
    """The charge of a battery fault, checked before anything is sent."""
    from vahr.errors import VahrError

    if fault != "battery":
        if given is not None:
            raise VahrError(f"{given!r}: only a battery fault takes a percent")
        return None
    if given is None:
        raise VahrError("battery needs the charge to set: vahr fault THING battery PERCENT")
    try:
        percent = float(given)
    except ValueError:
        raise VahrError(f"battery {given!r}: not a number; give a percent from 0 to 100") from None
    if not 0 <= percent <= 100:
        raise VahrError(f"battery {given}: a charge is 0 to 100 percent")
    return percent
