"""Candidate robots from AWS IoT fleet indexing: `vahr.dispatch.Candidates` on
`SearchIndex`, never reading a shadow.

Thing indexing with the classic shadow (REGISTRY_AND_SHADOW) and the custom fields
`shadow.reported.status`, `shadow.reported.zone`, `shadow.reported.connected` and
`shadow.reported.battery.*` (infra/constructs/fleet_indexing.py) lets one query find the
robots that may take a task; each ThingDocument carries the indexed shadow as JSON, so a
robot's pose, battery, connection and last command come with it.

A page holds at most 100 things, so reading every free robot of 10,000 costs 100 calls, one
after the other. Idle robots rank before every busy one (`vahr.dispatch.rank`), so a search
for a task asks for the connected idle robots first and stops after the first page that
holds one not already holding a task; only when no idle robot is free does it read the
busy ones. A task is then ranked among the (at least 100) idle robots of that page, not
among every idle robot of a larger fleet: the index has no order by distance. Orders that
need every robot of a kind (`every_robot`: "every idle robot", a group's members) and a
search within one zone read every page.

A robot out of service is the task table's, not the index's: `out_of_service` names them,
and they are left out of `available` and read as such (`RobotState.in_service` False) by
`state`. The schedule's `low_idle` asks for the idle robots whose charge is under the
fleet's threshold, by a range on the indexed charge (`shadow.reported.battery.percent<20`),
so the dispatcher can send them to charge: a page or two however large the fleet, where
reading every idle robot of 10,000 took 100 calls a minute.

The index follows the shadows within seconds, not at once: a robot that just left
`idle` may still be found. That is harmless here, since the task table's conditional
`assign`, not the index, decides who takes a task; the index only proposes.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import boto3
import msgspec
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from dispatcher.errors import SearchError
from vahr.dispatch import BUSY_STATUSES, IDLE_STATUSES, RobotState

# msgspec reads the annotations at run time: Pose and Battery are needed outside
# TYPE_CHECKING.
from vahr.domain.fleet import Pose  # noqa: TC001
from vahr.protocol.shadow import Battery  # noqa: TC001

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Iterator

CLIENT_CONFIG = Config(
    connect_timeout=2.0, read_timeout=5.0, retries={"mode": "standard", "total_max_attempts": 3}
)
# SearchIndex's largest page (AWS: maxResults "cannot exceed 100").
PAGE_SIZE = 100
STATUS_FIELD = "shadow.reported.status"
ZONE_FIELD = "shadow.reported.zone"
CONNECTED_FIELD = "shadow.reported.connected"
BATTERY_FIELD = "shadow.reported.battery.percent"
# AWS's limit on a query string's length: a search for many things by name is split.
MAX_QUERY_CHARS = 1000


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
    battery: Battery | None = None


class _Shadow(msgspec.Struct):
    reported: _Reported = msgspec.field(default_factory=_Reported)


class _Document(msgspec.Struct):
    state: _Shadow | None = None
    reported: _Reported | None = None


_SHADOW = msgspec.json.Decoder(_Document)


def robot_state(
    thing: str, reported: dict[str, Any] | _Reported | None, *, in_service: bool = True
) -> RobotState | None:
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
        battery=reported.battery,
        in_service=in_service,
    )


def available_query(zone: str | None = None) -> str:
    """The index query for robots that may take a task (idle or busy), in `zone` if given."""
    return status_query(IDLE_STATUSES | BUSY_STATUSES, zone)


def status_query(statuses: Iterable[str], zone: str | None = None) -> str:
    """The index query for connected robots reporting one of `statuses`, in `zone` if
    given."""
    terms = " OR ".join(f"{STATUS_FIELD}:{status}" for status in sorted(statuses))
    query = f"({terms}) AND {CONNECTED_FIELD}:true"
    if zone is not None:
        query += f" AND {ZONE_FIELD}:{_term(zone)}"
    return query


def low_query(below: float) -> str:
    """The index query for connected idle robots whose charge is under `below` percent."""
    return f"{status_query(IDLE_STATUSES)} AND {BATTERY_FIELD}<{below:g}"


def name_queries(things: Iterable[str]) -> list[str]:
    """Queries finding these things by name, each within AWS's query length."""
    queries: list[str] = []
    current = ""
    for thing in sorted(set(things)):
        term = f"thingName:{_term(thing)}"
        joined = f"{current} OR {term}" if current else term
        if len(joined) > MAX_QUERY_CHARS:
            queries.append(current)
            joined = term
        current = joined
    if current:
        queries.append(current)
    return queries


def _term(value: str) -> str:
    """A value as one term of the query syntax (zone ids are letters, digits, '_', '-')."""
    if not value or not all(ch.isalnum() or ch in "_-" for ch in value):
        raise SearchError(f"{value!r} cannot be searched for in the fleet index")
    return value


class FleetSearch:
    """`Candidates` on IoT fleet indexing (the `AWS_Things` index)."""

    def __init__(
        self,
        *,
        index_name: str = "AWS_Things",
        client: Any = None,
        holding: Callable[[], Iterable[str]] | None = None,
        usable: Callable[[RobotState], bool] | None = None,
        out_of_service: Callable[[], Iterable[str]] | None = None,
    ) -> None:
        """`holding` names the robots holding a task now (the task table's claims) and
        `usable` says whether the dispatcher would give a robot a task at all (a rule on
        its battery, say): a page whose idle robots all hold a task or are not usable is
        read past. Without them, every robot found counts as free. `out_of_service` names
        the robots out of service (the task table's), read once per search."""
        self._index = index_name
        self._client = client or boto3.client("iot", config=CLIENT_CONFIG)
        self._holding = holding
        self._usable = usable
        self._out_of_service = out_of_service
        self._every_robot = False

    @contextmanager
    def every_robot(self) -> Iterator[None]:
        """Within it, `available` reads every page: for orders that need every robot of a
        kind ("every idle robot") or only some robots (a group's members), which the first
        page of idle robots may not hold."""
        before, self._every_robot = self._every_robot, True
        try:
            yield
        finally:
            self._every_robot = before

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        out = self._out()
        if zone is not None or self._every_robot:
            return self._found(self._search(available_query(zone)), out)
        holding = set(self._holding()) if self._holding is not None else set()
        robots: list[RobotState] = []
        # Idle robots rank before every busy one: the busy are read only when no idle robot
        # is free, and each search stops after the first page holding a free robot.
        for statuses in (IDLE_STATUSES, BUSY_STATUSES):
            for page in self._pages(status_query(statuses)):
                found = self._found(page, out)
                robots.extend(found)
                usable = self._usable
                if any(
                    robot.thing not in holding and (usable is None or usable(robot))
                    for robot in found
                ):
                    return robots
        return robots

    def low_idle(self, below: float) -> list[RobotState]:
        """Every connected idle robot in service whose charge is under `below` percent:
        what the schedule reads to send them to charge."""
        out = self._out()
        found = self._found(self._search(low_query(below)), out)
        return [robot for robot in found if robot.idle]

    def state(self, thing: str) -> RobotState | None:
        return self.states([thing]).get(thing)

    def states(self, things: Iterable[str]) -> dict[str, RobotState]:
        """The state of each of `things` the index knows (and that reports a status), with
        one search per 40 or so names."""
        wanted = set(things)
        out = self._out() if wanted else frozenset()
        states: dict[str, RobotState] = {}
        for query in name_queries(wanted):
            for name, reported in self._search(query):
                found = name in wanted
                state = robot_state(name, reported, in_service=name not in out) if found else None
                if state is not None:
                    states[name] = state
        return states

    def in_service(self, state: RobotState) -> RobotState:
        """`state` (read elsewhere: the rule's event) with the table's word on its service."""
        if state.thing in self._out():
            return msgspec.structs.replace(state, in_service=False)
        return state

    def _out(self) -> frozenset[str]:
        return frozenset(self._out_of_service()) if self._out_of_service else frozenset()

    @staticmethod
    def _found(
        entries: Iterable[tuple[str, _Reported | None]], out: frozenset[str] = frozenset()
    ) -> list[RobotState]:
        found = (robot_state(*entry) for entry in entries if entry[0] not in out)
        # The index may lag a shadow by seconds; the state it holds is checked again here.
        return [robot for robot in found if robot is not None and robot.available]

    def _search(self, query: str) -> Iterator[tuple[str, _Reported | None]]:
        """(thing, reported state) of every thing the query finds, page after page."""
        for page in self._pages(query):
            yield from page

    def _pages(self, query: str) -> Iterator[list[tuple[str, _Reported | None]]]:
        """The things the query finds, one page (one SearchIndex call) at a time."""
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
            yield [
                (document.get("thingName", ""), _reported(document.get("shadow")))
                for document in page.get("things", [])
            ]
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
