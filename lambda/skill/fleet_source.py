"""Load the fleet at cold start, from the JSON twin of the bundled fleet.yaml when it is current.

`python -m vahr.skill_model` writes `fleet.json` next to this module with the SHA-256 of
the fleet.yaml it came from. Reading JSON spares the cold start PyYAML's import and parse;
if the bundled fleet.yaml no longer matches that hash (edited, twin not regenerated), the
YAML itself is read, so a stale twin can never change what the skill believes.
"""

from __future__ import annotations

import hashlib
import os

import msgspec

from skill.logs import log_event
from vahr.domain import DEFAULT_FLEET_FILE, Fleet, load_fleet
from vahr.protocol import ProtocolError

# os.path rather than pathlib: this runs on the cold-start path (see vahr.domain.fleet).
TWIN_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fleet.json")  # noqa: PTH100, PTH118, PTH120


class _Twin(msgspec.Struct):
    source_sha256: str
    fleet: Fleet
    generated_from: str = ""


def load(fleet_file: str | None = None, *, twin_file: str = TWIN_FILE) -> Fleet:
    """The configured fleet file, else the bundled fleet (through its twin when current)."""
    if fleet_file:
        return load_fleet(fleet_file)
    try:
        with open(DEFAULT_FLEET_FILE, "rb") as source, open(twin_file, "rb") as twin_stream:  # noqa: PTH123
            digest = hashlib.sha256(source.read()).hexdigest()
            twin = msgspec.json.decode(twin_stream.read(), type=_Twin)
        if twin.source_sha256 == digest:
            return twin.fleet.validate()
        log_event("fleet_twin_stale", twin=twin_file, fleet=DEFAULT_FLEET_FILE)
    except (OSError, msgspec.DecodeError, msgspec.ValidationError, ProtocolError) as err:
        log_event("fleet_twin_unusable", twin=twin_file, error=str(err))
    return load_fleet()
