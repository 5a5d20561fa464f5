"""`--fleet FILE`, the flag of every command that reads a fleet, and the fleet a running
`vahr up` serves (`GET /vahr/fleet`) to the commands pointed at it with `--api`.

A command that starts its own system (`up`, `demo`, `rehearse` without `--api`) runs the
file it is given; one that works beside a running stack (`station`, `experiment`, `rehearse`
with `--api`) takes that stack's fleet unless told otherwise, so a fleet is named once, to
`vahr up`. A bad file is one line naming the file, the entry and the reason.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from vahr.domain import Fleet, load_fleet
from vahr.domain.fleet import map_beside
from vahr.errors import VahrError
from vahr.protocol import ProtocolError

if TYPE_CHECKING:
    import argparse

# `GET` on a local stack's data plane: {"fleet": the fleet it runs, as fleet.yaml's keys}.
FLEET_ROUTE = "/vahr/fleet"
# How long a command waits for a stack to say its fleet before taking the bundled one.
SERVED_TIMEOUT_S = 5.0


def add_fleet_flag(parser: argparse.ArgumentParser, *, beside_a_stack: bool = False) -> None:
    default = "the running stack's (--api), else fleet.yaml" if beside_a_stack else "fleet.yaml"
    parser.add_argument(
        "--fleet",
        type=Path,
        metavar="FILE",
        help=f"fleet file: robots, zones, groups, floor (default: {default})",
    )


def read_fleet(path: Path | None) -> Fleet:
    """The fleet in `path`, validated (the bundled fleet.yaml when None)."""
    if path is None:
        return load_fleet()
    try:
        text = path.read_bytes()
    except OSError as err:
        raise VahrError(f"{path}: cannot read the fleet file ({err.strerror})") from err
    try:
        return map_beside(Fleet.from_yaml(text), path)
    except ProtocolError as err:
        # The whole file's faults ("is not valid YAML") need no field name after the file's.
        said = err.reason if err.field == "fleet" else str(err)
        raise VahrError(f"{path}: {said}") from err


def read_fleet_on_its_floor(path: Path | None) -> Fleet:
    """`read_fleet`, and a floor that is a map read and the fleet checked against it: a
    bad map, or a robot or zone where no robot can be on it, is one line naming the file."""
    from vahr.navigation import MapError, load_floor

    fleet = read_fleet(path)
    try:
        load_floor(fleet)
    except MapError as err:
        raise VahrError(f"{path or 'fleet.yaml'}: {err}") from err
    return fleet


def served_fleet(api: str) -> Fleet | None:
    """The fleet the local stack at `api` runs, or None when `api` serves none (AWS's
    iot-data endpoint, a stack from before the route, nothing at all)."""
    import msgspec

    from vahr.plumbing.client import call

    try:
        answer = call(api, "GET", FLEET_ROUTE, timeout_s=SERVED_TIMEOUT_S)
    except VahrError:
        return None
    try:
        return msgspec.convert(answer.get("fleet"), type=Fleet).validate()
    except (msgspec.ValidationError, ProtocolError) as err:
        raise VahrError(f"the fleet {api}{FLEET_ROUTE} serves is not valid: {err}") from err


def fleet_for(path: Path | None, api: str | None) -> Fleet:
    """`--fleet` when given; else the fleet of the stack at `api`; else the bundled one."""
    if path is None and api is not None:
        served = served_fleet(api)
        if served is not None:
            return served
    return read_fleet(path)
