"""Candidate robots from AWS IoT fleet indexing: `vahr.dispatch.Candidates` on
`SearchIndex`, never reading a shadow.

Thing indexing with the classic shadow (REGISTRY_AND_SHADOW) and the custom fields
`shadow.reported.status` and `shadow.reported.zone` (infra/constructs/fleet_indexing.py)
lets one query find the robots that may take a task; each ThingDocument carries the
indexed shadow as JSON, so a robot's pose, connection and last command come with it. A
page holds at most 100 things, so 1,000 free robots cost 10 calls.

The index follows the shadows within seconds, not at once: a robot that just left
`idle` may still be found. That is harmless here, since the task table's conditional
`assign`, not the index, decides who takes a task; the index only proposes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
import msgspec
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from dispatcher.errors import SearchError
from vahr.dispatch import BUSY_STATUSES, IDLE_STATUSES, RobotState

# msgspec reads the annotations at run time: Pose is needed outside TYPE_CHECKING.
from vahr.domain.fleet import Pose  # noqa: TC001

if TYPE_CHECKING:
    from collections.abc import Iterator

CLIENT_CONFIG = Config(
    connect_timeout=2.0, read_timeout=5.0, retries={"mode": "standard", "total_max_attempts": 3}
)
# SearchIndex's largest page (AWS: maxResults "cannot exceed 100").
PAGE_SIZE = 100
STATUS_FIELD = "shadow.reported.status"
ZONE_FIELD = "shadow.reported.zone"


class _LastCommand(msgspec.Struct):
    id: str | None = None
    result: str | None = None


class _Reported(msgspec.Struct):
    """The parts of a robot's reported state the dispatcher uses; the rest is ignored."""

    status: str | None = None
    zone: str | None = None
    connected: bool = False
    pose: Pose | None = None
    last_command: _LastCommand | None = None


class _Shadow(msgspec.Struct):
    reported: _Reported = msgspec.field(default_factory=_Reported)


class _Document(msgspec.Struct):
    state: _Shadow | None = None
    reported: _Reported | None = None


_SHADOW = msgspec.json.Decoder(_Document)


def robot_state(thing: str, reported: dict[str, Any] | _Reported | None) -> RobotState | None:
    """A robot's reported state as the dispatcher's `RobotState`; None without a status."""
    if reported is None:
        return None
    if isinstance(reported, dict):
        try:
            reported = msgspec.convert(reported, _Reported, strict=False)
        except msgspec.ValidationError:
            return None
    if reported.status is None:
        return None
    last = reported.last_command
    return RobotState(
        thing=thing,
        status=reported.status,
        connected=reported.connected,
        zone=reported.zone,
        pose=reported.pose,
        last_command_id=last.id if last else None,
        last_result=last.result if last else None,
    )


def available_query(zone: str | None = None) -> str:
    """The index query for robots that may take a task (idle or busy), in `zone` if given."""
    free = sorted(IDLE_STATUSES | BUSY_STATUSES)
    statuses = " OR ".join(f"{STATUS_FIELD}:{status}" for status in free)
    query = f"({statuses})"
    if zone is not None:
        query += f" AND {ZONE_FIELD}:{_term(zone)}"
    return query


def _term(value: str) -> str:
    """A value as one term of the query syntax (zone ids are letters, digits, '_', '-')."""
    if not value or not all(ch.isalnum() or ch in "_-" for ch in value):
        raise SearchError(f"{value!r} cannot be searched for in the fleet index")
    return value


class FleetSearch:
    """`Candidates` on IoT fleet indexing (the `AWS_Things` index)."""

    def __init__(self, *, index_name: str = "AWS_Things", client: Any = None) -> None:
        self._index = index_name
        self._client = client or boto3.client("iot", config=CLIENT_CONFIG)

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        found = (robot_state(*entry) for entry in self._search(available_query(zone)))
        # The index may lag a shadow by seconds; the state it holds is checked again here.
        return [robot for robot in found if robot is not None and robot.available]

    def state(self, thing: str) -> RobotState | None:
        for name, reported in self._search(f"thingName:{_term(thing)}"):
            if name == thing:
                return robot_state(name, reported)
        return None

    def _search(self, query: str) -> Iterator[tuple[str, _Reported | None]]:
        """(thing, reported state) of every thing the query finds, page after page."""
        request: dict[str, Any] = {
            "indexName": self._index,
            "queryString": query,
            "maxResults": PAGE_SIZE,
        }
        while True:
            try:
                page = self._client.search_index(**request)
            except ClientError as err:
                error = err.response.get("Error", {})
                raise SearchError(
                    f"the fleet index did not answer {query!r}: "
                    f"{error.get('Code')}: {error.get('Message')}"
                ) from err
            except BotoCoreError as err:
                raise SearchError(f"the fleet index did not answer {query!r}: {err}") from err
            for document in page.get("things", []):
                yield document.get("thingName", ""), _reported(document.get("shadow"))
            token = page.get("nextToken")
            if not token:
                return
            request["nextToken"] = token


def _reported(shadow: str | None) -> _Reported | None:
    """The reported state in a ThingDocument's `shadow` (JSON text). AWS writes the shadow
    document there ({"reported": ..., "metadata": ..., "version": ...}); a document in the
    full `{"state": {"reported": ...}}` form is read too."""
    if not shadow:
        return None
    try:
        document = _SHADOW.decode(shadow)
    except (msgspec.DecodeError, msgspec.ValidationError):
        return None
    if document.reported is not None:
        return document.reported
    return document.state.reported if document.state is not None else None
