"""The local stack's fleet dispatcher: the core of `vahr.dispatch` wired to `vahr up`.

- tasks: `SqliteTaskStore` in the state directory (the queue survives a restart);
- candidates: the local fleet index the shadow store keeps (`IndexCandidates`), the twin
  of IoT fleet indexing on AWS;
- robot freed: every `update/documents` of a classic shadow on the broker (what the IoT
  rule feeds the dispatcher Lambda on AWS) hands that robot's indexed state to
  `Dispatcher.observe`, on a worker thread of its own;
- publish: the command on `vahr/robots/{thing}/cmd`, QoS 1, waiting for the broker's PUBACK.

The data plane serves it (`TasksApi`) under `/vahr/tasks`: `POST` submits an order
(answers the `Submission`), `GET` lists the tasks robots hold then the queue
(`{"tasks": [...], "closed": [zone ids], "out_of_service": [things]}`), `DELETE
/vahr/tasks/{id}` cancels one; and
under `/vahr/zones` (`ZonesApi`): `GET` answers `{"closed": [zone ids]}`, `POST
/vahr/zones/{zone}` with `{"closed": true|false}` closes or opens one (answers the
`ZoneChange`). Closures live in the same SQLite file, and every change is published,
retained, on `vahr/fleet/zones` for the robots.

On a map (`floor: {map: FILE}`), the cost of a robot is its planned path's length:
`vahr.navigation`'s distance field from each zone, one search per zone and set of closed
zones, cached.

Each order, cancel and zone change that reaches the API is recorded in the audit trail
(channel `api`), unless its sender recorded it already (the skill and the station do, with
the person who asked: they say so in `RECORDED_BY_HEADER`); so is each queued task the
dispatcher gives a robot by itself once one comes free (channel `dispatcher`).
"""

from __future__ import annotations

import logging
import queue
import threading
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.dispatch import (
    BUSY_STATUSES,
    IDLE_STATUSES,
    Dispatcher,
    DispatchError,
    Order,
    RobotState,
)
from vahr.dispatch.records import task_given
from vahr.dispatch.tasks import timestamp
from vahr.domain import Pose
from vahr.local.task_store import SqliteTaskStore
from vahr.navigation import load_floor
from vahr.plumbing.mqtt import MqttClient
from vahr.protocol import Battery, encode, topics, utc_now
from vahr.protocol.audit import RECORDED_BY_HEADER, AuditEntry, Outcome, now
from vahr.protocol.errors import from_validation_error
from vahr.twin import identities

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Mapping
    from pathlib import Path

    from vahr.dispatch import Task
    from vahr.dispatch.dispatcher import ServiceChange
    from vahr.domain import Fleet
    from vahr.plumbing.mqtt import MqttEndpoint
    from vahr.protocol import Command, ZoneClosures
    from vahr.twin.fleet_index import FleetIndex, IndexedThing

log = logging.getLogger(__name__)

TASKS_PATH = "/vahr/tasks"
ZONES_PATH = "/vahr/zones"
SERVICE_PATH = "/vahr/service"
CHARGE_PATH = "/vahr/charge"
STOP_TIMEOUT_S = 5.0

Answer = tuple[int, bytes, str | None]
# Who acts when no person does: a program calling the tasks API, the dispatcher itself.
API_CALLER = "api"


def robot_state(entry: IndexedThing, *, in_service: bool = True) -> RobotState:
    """A fleet index entry as the dispatcher reads it."""
    pose = entry.pose
    return RobotState(
        thing=entry.thing,
        status=entry.status or "unknown",
        connected=entry.connected,
        zone=entry.zone,
        pose=Pose(pose.x, pose.y, pose.theta) if pose is not None else None,
        last_command_id=entry.command_id,
        last_result=entry.command_result,
        battery=reported_battery(entry.reported.get("battery")),
        in_service=in_service,
    )


def reported_battery(value: object) -> Battery | None:
    """`reported.battery` as the robot wrote it; None when it wrote none or not one."""
    if not isinstance(value, dict):
        return None
    percent, charging = value.get("percent"), value.get("charging", False)
    if isinstance(percent, bool) or not isinstance(percent, int | float) or not 0 <= percent <= 100:
        return None
    return Battery(percent=round(percent), charging=charging is True)


class IndexCandidates:
    """`Candidates` over the local fleet index: only the fleet's robots, only what the index's
    secondary indexes (by status, by zone) return, so a question costs its answer's size."""

    def __init__(self, index: FleetIndex, fleet: Fleet) -> None:
        self.index = index
        self.robots = frozenset(fleet.robot_things)
        # The robots out of service (`set_out_of_service`; the store keeps them).
        self.out_of_service: frozenset[str] = frozenset()
        # Each robot's state as last read, with the index entry it was read from: entries
        # are replaced, never changed, on every update, so an unchanged robot costs one
        # identity check instead of a new state (most of the time at 10,000 robots).
        self._read: dict[str, tuple[IndexedThing, RobotState]] = {}

    def set_out_of_service(self, things: Iterable[str]) -> None:
        self.out_of_service = frozenset(things)
        self._read.clear()

    def _state(self, entry: IndexedThing) -> RobotState:
        read = self._read.get(entry.thing)
        if read is not None and read[0] is entry:
            return read[1]
        state = robot_state(entry, in_service=entry.thing not in self.out_of_service)
        self._read[entry.thing] = (entry, state)
        return state

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        if zone is not None:
            entries = self.index.in_zone(zone)
        else:
            entries = []
            for status in sorted(IDLE_STATUSES | BUSY_STATUSES):
                entries += self.index.with_status(status)
        robots, takes, read = self.robots, IDLE_STATUSES | BUSY_STATUSES, self._read
        out = self.out_of_service
        states = []
        for entry in entries:
            if not (entry.connected and entry.status in takes and entry.thing in robots):
                continue
            if out and entry.thing in out:
                continue
            known = read.get(entry.thing)
            fresh = known is not None and known[0] is entry
            states.append(known[1] if fresh else self._state(entry))  # type: ignore[index]
        return states

    def state(self, thing: str) -> RobotState | None:
        entry = self.index.get(thing)
        return self._state(entry) if entry is not None and thing in self.robots else None


class _RecordedApi:
    """A data-plane route whose changes a program asks for are recorded in the audit trail
    (`record`), unless their sender recorded them itself (`_recorded_by_sender`).
    Subclasses answer in `_respond` and make the record in `_entry`."""

    # The methods that change something, and so are recorded.
    RECORDED_METHODS: tuple[str, ...] = ("POST",)

    def __init__(self, record: Callable[[AuditEntry], object] | None) -> None:
        self._record = record

    def respond(
        self, method: str, path: str, body: bytes, headers: Mapping[str, str] | None = None
    ) -> Answer:
        answer = self._respond(method, path, body)
        recorded = _recorded_by_sender(headers)
        if self._record is not None and method in self.RECORDED_METHODS and not recorded:
            self._record(self._entry(method, path, body, answer))
        return answer

    def _respond(self, method: str, path: str, body: bytes) -> Answer:
        raise NotImplementedError

    def _entry(self, method: str, path: str, body: bytes, answer: Answer) -> AuditEntry:
        raise NotImplementedError


class TasksApi(_RecordedApi):
    """`/vahr/tasks` on the data plane, in its typed-route form: (status, body, error type).
    `record`, when given, takes the trail's entry for each order and cancel;
    `out_of_service` says which robots are out of service, for the list."""

    def __init__(
        self,
        dispatcher: Dispatcher,
        record: Callable[[AuditEntry], object] | None = None,
        out_of_service: Callable[[], list[str]] | None = None,
    ) -> None:
        super().__init__(record)
        self.dispatcher = dispatcher
        self._out_of_service = out_of_service

    RECORDED_METHODS = ("POST", "DELETE")

    def _entry(self, method: str, path: str, body: bytes, answer: Answer) -> AuditEntry:
        return _api_entry(method, path, body, answer)

    def _respond(self, method: str, path: str, body: bytes) -> Answer:
        if path == TASKS_PATH:
            if method == "GET":
                closed = self.dispatcher.closed_zones()
                out = self._out_of_service() if self._out_of_service is not None else []
                tasks = self.dispatcher.tasks()
                return _ok({"tasks": tasks, "closed": closed, "out_of_service": out})
            if method == "POST":
                return self._submit(body)
            return _error(405, f"{method} is not allowed on {TASKS_PATH}")
        task_id = path[len(TASKS_PATH) + 1 :]
        if "/" in task_id or not task_id:
            return _error(404, f"No route for {method} {path}")
        if method != "DELETE":
            return _error(405, f"{method} is not allowed on a task; DELETE cancels it")
        cancelled = self.dispatcher.cancel(task_id)
        if cancelled is None:
            return _error(404, f"no open task {task_id!r}")
        return _ok({"task": cancelled})

    def _submit(self, body: bytes) -> Answer:
        try:
            order = msgspec.json.decode(body or b"{}", type=Order)
        except (msgspec.ValidationError, msgspec.DecodeError) as err:
            return _error(400, str(from_validation_error(err)))
        try:
            return _ok(self.dispatcher.submit(order))
        except DispatchError as err:
            return _error(400, str(err), error=err.code)


class ZoneRequest(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The body of `POST /vahr/zones/{zone}`."""

    closed: bool


class ZonesApi(_RecordedApi):
    """`/vahr/zones` on the data plane: the zones closed at run time. `record`, when given,
    takes the trail's entry for each change asked for."""

    def __init__(
        self, dispatcher: Dispatcher, record: Callable[[AuditEntry], object] | None = None
    ) -> None:
        super().__init__(record)
        self.dispatcher = dispatcher

    def _entry(self, method: str, path: str, body: bytes, answer: Answer) -> AuditEntry:
        return _zone_entry(path, body, answer)

    def _respond(self, method: str, path: str, body: bytes) -> Answer:
        if path == ZONES_PATH:
            if method == "GET":
                return _ok({"closed": self.dispatcher.closed_zones()})
            return _error(405, f"{method} is not allowed on {ZONES_PATH}")
        zone = path[len(ZONES_PATH) + 1 :]
        if "/" in zone or not zone:
            return _error(404, f"No route for {method} {path}")
        if method != "POST":
            return _error(405, f'{method} is not allowed on a zone; POST {{"closed": ...}}')
        try:
            request = msgspec.json.decode(body or b"{}", type=ZoneRequest)
        except (msgspec.ValidationError, msgspec.DecodeError) as err:
            return _error(400, str(from_validation_error(err)))
        try:
            return _ok(self.dispatcher.set_zone(zone, closed=request.closed))
        except DispatchError as err:
            return _error(400, str(err), error=err.code)


def _recorded_by_sender(headers: Mapping[str, str] | None) -> bool:
    """Whether the request's sender recorded it in the trail itself (with its person)."""
    return any(name.lower() == RECORDED_BY_HEADER.lower() for name in headers or {})


class ServiceRequest(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The body of `POST /vahr/service/{thing}`."""

    in_service: bool


class RobotsApi(_RecordedApi):
    """`/vahr/service` and `/vahr/charge` on the data plane: robots out of service and back
    (`GET /vahr/service` answers `{"out_of_service": [things]}`, `POST /vahr/service/{thing}`
    with `{"in_service": true|false}` answers the `ServiceChange`) and a robot sent to charge
    now (`POST /vahr/charge/{thing}` answers `{"task": Task}`). `record`, when given, takes
    the trail's entry for each change asked for by a program."""

    def __init__(
        self, host: LocalDispatcher, record: Callable[[AuditEntry], object] | None = None
    ) -> None:
        super().__init__(record)
        self.host = host

    def _entry(self, method: str, path: str, body: bytes, answer: Answer) -> AuditEntry:
        return _robot_entry(path, body, answer)

    def _respond(self, method: str, path: str, body: bytes) -> Answer:
        if path == SERVICE_PATH:
            if method == "GET":
                return _ok({"out_of_service": self.host.tasks.out_of_service()})
            return _error(405, f"{method} is not allowed on {SERVICE_PATH}")
        base = SERVICE_PATH if path.startswith(SERVICE_PATH + "/") else CHARGE_PATH
        thing = path[len(base) + 1 :]
        if "/" in thing or not thing:
            return _error(404, f"No route for {method} {path}")
        if method != "POST":
            return _error(405, f"{method} is not allowed on {path}; POST")
        if thing not in self.host.candidates.robots:
            return _error(404, f"{thing[:40]} is not a robot of the fleet", error="unknown_robot")
        if base == CHARGE_PATH:
            try:
                task = self.host.dispatcher.charge(thing, asked=True)
            except DispatchError as err:
                return _error(400, str(err), error=err.code)
            return _ok({"task": task})
        try:
            request = msgspec.json.decode(body or b"{}", type=ServiceRequest)
        except (msgspec.ValidationError, msgspec.DecodeError) as err:
            return _error(400, str(from_validation_error(err)))
        return _ok(self.host.set_in_service(thing, request.in_service))


def _robot_entry(path: str, body: bytes, answer: Answer) -> AuditEntry:
    """The trail's record of a robot taken out of service, put back or sent to charge
    through the API by a program."""
    status, payload, _ = answer
    answered = _json_object(payload)
    charge = path.startswith(CHARGE_PATH + "/")
    thing = path.rsplit("/", 1)[-1][:255]
    in_service = _json_object(body).get("in_service")
    intent = "charge" if charge else "back_in_service" if in_service else "out_of_service"
    task = answered.get("task") if charge else None
    return AuditEntry(
        time=now(),
        who=API_CALLER,
        channel="api",
        words=f"POST {path}",
        intent=intent,
        slots={"robot": thing},
        robots=[thing] if status == 200 else [],
        commands=[str(task.get("id"))] if isinstance(task, dict) else [],
        outcome="sent" if status == 200 else "failed",
        reason=None if status == 200 else str(answered.get("message", f"HTTP {status}"))[:500],
    )


def _api_entry(method: str, path: str, body: bytes, answer: Answer) -> AuditEntry:
    """The trail's record of one order or cancel sent to the API by a program."""
    status, payload, _ = answer
    outcome: Outcome = "sent" if status == 200 else "failed"
    reason = None
    robots: list[str] = []
    commands: list[str] = []
    slots: dict[str, str | None] = {}
    answered = _json_object(payload)
    if status != 200:
        reason = str(answered.get("message", f"HTTP {status}"))[:500]
    if method == "POST":
        order = _json_object(body)
        slots = {str(k)[:255]: str(v)[:255] for k, v in order.items() if v is not None}
        tasks = [*answered.get("assigned", []), *answered.get("queued", [])]
        commands = [str(task.get("id")) for task in tasks if isinstance(task, dict)]
        robots = [str(t["thing"]) for t in answered.get("assigned", []) if t.get("thing")]
    else:
        task = answered.get("task") or {}
        commands = [path[len(TASKS_PATH) + 1 :][:255]]
        robots = [str(task["thing"])] if task.get("thing") else []
    return AuditEntry(
        time=now(),
        who=API_CALLER,
        channel="api",
        words=f"{method} {path}",
        intent="submit" if method == "POST" else "cancel",
        slots=slots,
        robots=robots,
        commands=commands,
        outcome=outcome,
        reason=reason,
    )


def _zone_entry(path: str, body: bytes, answer: Answer) -> AuditEntry:
    """The trail's record of one zone closed or opened through the API by a program."""
    status, payload, _ = answer
    answered = _json_object(payload)
    closed = _json_object(body).get("closed")
    given = [task for task in answered.get("given", []) if isinstance(task, dict)]
    return AuditEntry(
        time=now(),
        who=API_CALLER,
        channel="api",
        words=f"POST {path}",
        intent="close_zone" if closed is True else "open_zone" if closed is False else "zone",
        slots={"zone": path[len(ZONES_PATH) + 1 :][:255]},
        robots=[str(task["thing"]) for task in given if task.get("thing")],
        commands=[str(task.get("id")) for task in given],
        outcome="sent" if status == 200 else "failed",
        reason=None if status == 200 else str(answered.get("message", f"HTTP {status}"))[:500],
    )


def _json_object(data: bytes) -> dict[str, Any]:
    """`data` as a JSON object, or an empty one when it is not one (a record never fails)."""
    try:
        value = msgspec.json.decode(data or b"{}")
    except msgspec.DecodeError:
        return {}
    return value if isinstance(value, dict) else {}


def _ok(body: object) -> Answer:
    return 200, msgspec.json.encode(body), None


def _error(status: int, message: str, *, error: str | None = None) -> Answer:
    """A refusal in the data plane's shape; `error` is the `DispatchError.code` of a refused
    order, which the skill decides by."""
    error_type = {400: "InvalidRequestException", 404: "ResourceNotFoundException"}.get(
        status, "MethodNotAllowedException"
    )
    body: dict[str, object] = {"code": status, "message": message}
    if error is not None:
        body["error"] = error
    return status, msgspec.json.encode(body), error_type


class LocalDispatcher:
    """The dispatcher on the local broker: its own client, its shadow subscription and the
    worker thread that hands robots' updates to the core. A context manager."""

    def __init__(
        self,
        *,
        fleet: Fleet,
        index: FleetIndex,
        endpoint: MqttEndpoint,
        state_dir: Path,
        on_given_up: Callable[[Task], None] | None = None,
        on_charging: Callable[[Task], None] | None = None,
        record: Callable[[AuditEntry], object] | None = None,
    ) -> None:
        """`on_given_up`: told each task given up because its robot was sent elsewhere;
        `on_charging`: told each robot the dispatcher sends to charge by itself."""
        self.tasks = SqliteTaskStore.in_state_dir(state_dir)
        self._record = record
        self.candidates = IndexCandidates(index, fleet)
        self.candidates.set_out_of_service(self.tasks.out_of_service())
        self._service_lock = threading.Lock()
        self._client = MqttClient(endpoint, client_id=identities.DISPATCHER)
        floor = load_floor(fleet)
        self.dispatcher = Dispatcher(
            fleet=fleet,
            store=self.tasks,
            candidates=self.candidates,
            publish=self._publish,
            on_given_up=on_given_up,
            on_charging=on_charging,
            routes=floor.routes if floor is not None else None,
            publish_closures=self._publish_closures,
        )
        self.api = TasksApi(self.dispatcher, record, self.tasks.out_of_service)
        self.zones_api = ZonesApi(self.dispatcher, record)
        self.robots_api = RobotsApi(self, record)
        self._updates: queue.SimpleQueue[str | None] = queue.SimpleQueue()
        self._worker: threading.Thread | None = None

    def set_in_service(self, thing: str, in_service: bool) -> ServiceChange:
        """Take `thing` out of service, or put it back: recorded in the store, then the
        dispatcher reads it so (`RobotState.in_service`) and acts on it."""
        with self._service_lock:
            changed = self.tasks.set_in_service(thing, in_service, at=timestamp(utc_now()))
            self.candidates.set_out_of_service(self.tasks.out_of_service())
        if not changed:
            return self.dispatcher.service_kept(thing, in_service)
        if in_service:
            change = self.dispatcher.reinstated(thing)
            self._recorded(change.given)
            return change
        change = self.dispatcher.withdrawn(thing)
        self._recorded([task for task in change.reassigned if task.thing is not None])
        return change

    def _publish(self, thing: str, command: Command) -> None:
        # Waits for the broker's PUBACK and raises when none comes: the task keeps its place.
        self._client.publish(topics.robot_cmd(thing), encode(command), qos=1, wait=True)

    def _publish_closures(self, closures: ZoneClosures) -> None:
        # Retained: a robot that starts or reconnects later learns the closures at once.
        self._client.publish(topics.FLEET_ZONES, encode(closures), qos=1, retain=True, wait=True)

    def _on_documents(self, topic: str, payload: bytes) -> None:
        # On paho's network thread: only note which robot changed; the index already holds
        # its new state (the shadow store records it before the update is announced).
        parsed = topics.parse_shadow_topic(topic)
        if parsed is not None and parsed[1] is None:
            self._updates.put(parsed[0])

    def _serve(self) -> None:
        while (thing := self._updates.get()) is not None:
            state = self.candidates.state(thing)
            if state is None:
                continue
            try:
                given = self.dispatcher.observe(state)
            except Exception:  # one failed hand-over must not stop the dispatcher
                log.exception("dispatching after an update of %s failed", thing)
                continue
            if given is not None:
                self._recorded([given])

    def _recorded(self, tasks: list[Task]) -> None:
        """Record tasks the dispatcher gave robots by itself (never stopping it)."""
        if self._record is None:
            return
        for task in tasks:
            try:
                self._record(task_given(task))
            except Exception:
                log.exception("the audit trail did not take the dispatch of %s", task.id)

    def start(self) -> LocalDispatcher:
        self._client.subscribe(topics.ALL_SHADOW_DOCUMENTS, self._on_documents, retained=False)
        self._client.connect()
        self._worker = threading.Thread(target=self._serve, name="vahr-dispatcher", daemon=True)
        self._worker.start()
        # What a previous run left: the zones closed (told to the robots, retained), commands
        # assigned but never acknowledged go out again (same ids: a robot that had one runs
        # it once), then queued tasks to free robots.
        self.dispatcher.announce_closures()
        self._recorded(self.dispatcher.resume())
        self._recorded(self.dispatcher.drain())
        return self

    def stop(self) -> None:
        worker, self._worker = self._worker, None
        if worker is not None:
            self._updates.put(None)
            worker.join(STOP_TIMEOUT_S)
        self._client.stop()
        self.tasks.close()

    def __enter__(self) -> LocalDispatcher:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
