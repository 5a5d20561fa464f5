"""The dispatcher's Lambda handler. Thin: parse the event, run the core, answer.

Three callers (see `dispatcher.requests`): the skill, synchronously, the topic rule on the
robots' shadow documents, and an EventBridge schedule once a minute. A task the fleet
loses (its robot sent elsewhere by name, gone offline, or never acknowledging it) is told
to the announcer function (`announcer_channel`), never closed without a word. Errors are
mapped
here and nowhere else: a request that cannot be carried out (a bad order, an unknown
task) is answered with its one line, and the skill speaks it; an AWS failure raises, so a
rule's event is retried by Lambda and then kept in the dead-letter queue, and the skill
hears that the dispatcher failed.
"""

from __future__ import annotations

import logging
from contextlib import AbstractContextManager, nullcontext
from datetime import UTC, datetime
from functools import cache
from typing import TYPE_CHECKING, Any

import msgspec

from dispatcher.announcer_channel import AnnouncerChannel, gone_to_charge
from dispatcher.command_channel import CommandChannel
from dispatcher.config import DispatcherConfig
from dispatcher.errors import BadRequest, ConfigError, DispatcherError
from dispatcher.fleet_search import FleetSearch, robot_state
from dispatcher.reoffer import watch_assigned
from dispatcher.requests import (
    OPERATIONS,
    Answer,
    Cancel,
    Charge,
    ListClosed,
    ListOutOfService,
    ListPending,
    ListTasks,
    RobotUpdate,
    SetService,
    SetZone,
    SkillRequest,
    Submit,
    is_robot_update,
    is_tick,
)
from dispatcher.robot_updates import robot_freed
from dispatcher.service import out_of_service, set_in_service
from dispatcher.task_table import TaskTable
from dispatcher.trail_table import TrailTable
from vahr.dispatch import Dispatcher, DispatchError, Task
from vahr.dispatch.grid_routes import DistancesError, floor_routes
from vahr.dispatch.records import task_given
from vahr.domain import load_fleet
from vahr.protocol.errors import ProtocolError, from_validation_error
from vahr.protocol.lost_tasks import LostTask

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.protocol.lost_tasks import Tidings

log = logging.getLogger("dispatcher")


@cache
def runtime() -> Dispatcher:
    """Built once per cold start: configuration, fleet, adapters, the core."""
    config = DispatcherConfig.from_env()
    log.setLevel(config.log_level)
    try:
        fleet = load_fleet(config.fleet_file)
    except ProtocolError as err:
        raise ConfigError(f"the fleet file {config.fleet_file or '(bundled)'}: {err}") from err
    try:
        routes = floor_routes(fleet, config.distances_file)
    except DistancesError as err:
        raise ConfigError(f"the fleet's map: {err}") from err
    channel = CommandChannel(config.iot_data_endpoint)
    table = TaskTable(config.table, closed_task_days=config.closed_task_days)
    # The search reads past a page of robots the dispatcher would not give a task (low,
    # out of service): the dispatcher's own test, bound once it exists.
    search = FleetSearch(
        index_name=config.index_name,
        holding=table.holders,
        usable=lambda robot: dispatcher.usable(robot),
        out_of_service=table.out_of_service,
    )
    dispatcher = Dispatcher(
        fleet=fleet,
        store=table,
        candidates=search,
        publish=channel,
        routes=lambda closed: routes,
        publish_closures=channel.closures,
    )
    return dispatcher


@cache
def trail() -> TrailTable | None:
    """Where the dispatcher records what it does by itself (None: no audit table)."""
    table = DispatcherConfig.from_env().audit_table
    return TrailTable(table) if table else None


@cache
def announcer() -> Callable[[Tidings], None]:
    """Where lost tasks and robots gone to charge are told: the announcer function, or
    only the log without one."""
    function = DispatcherConfig.from_env().announcer_function
    return AnnouncerChannel(function) if function else _logged_only


def _logged_only(tidings: Tidings) -> None:
    what = (
        f"task {tidings.task} lost ({tidings.why})"
        if isinstance(tidings, LostTask)
        else f"{tidings.thing} gone to charge"
    )
    log.warning("%s is not announced: no announcer function (VAHR_ANNOUNCER_FUNCTION)", what)


def lambda_handler(event: dict[str, Any], context: object) -> dict[str, Any]:
    try:
        return handle(event, runtime(), trail(), announcer())
    except DispatcherError as err:
        log.error("dispatcher failed: %s", err)
        raise
    except Exception as err:  # a bug: still one line in the log, still retried
        log.exception("dispatcher failed")
        raise DispatcherError(f"dispatcher failed: {type(err).__name__}: {err}") from err


def handle(
    event: dict[str, Any],
    dispatcher: Dispatcher,
    trail: TrailTable | None = None,
    tell: Callable[[Tidings], None] = _logged_only,
) -> dict[str, Any]:
    """One invocation: a robot's update (from the rule), the schedule's tick, or a skill's
    request. What the dispatcher does by itself (a queued task given to a robot) goes to
    `trail`, and a task it loses to `tell`; a skill's request is recorded by the skill,
    with who asked."""
    if is_robot_update(event):
        return on_robot_update(event, dispatcher, trail, tell)
    if is_tick(event):
        return on_tick(dispatcher, trail, tell)
    try:
        answer = on_request(_request(event), dispatcher, trail)
    except BadRequest as err:
        refusal: dict[str, Any] = {"code": err.status, "message": str(err)}
        if err.error is not None:
            refusal["error"] = err.error
        answer = Answer(err.status, refusal)
    return msgspec.to_builtins(answer)  # type: ignore[no-any-return]


def on_robot_update(
    event: dict[str, Any],
    dispatcher: Dispatcher,
    trail: TrailTable | None = None,
    tell: Callable[[Tidings], None] = _logged_only,
) -> dict[str, Any]:
    """A robot's update the rule selected: it may have finished its task and be free."""
    try:
        update = msgspec.convert(event, RobotUpdate, strict=False)
    except msgspec.ValidationError as err:
        # Retrying cannot mend a malformed event: logged and dropped.
        log.warning("ignoring a malformed robot update: %s", err)
        return {"took": None}
    state = robot_state(update.thing, update.reported)
    if state is None or update.thing not in dispatcher.fleet.robot_things:
        log.warning("ignoring an update of %s, which is not a robot of the fleet", update.thing)
        return {"took": None}
    if isinstance(dispatcher.candidates, FleetSearch):
        state = dispatcher.candidates.in_service(state)
    now = datetime.now(UTC)
    taken = robot_freed(dispatcher, state, now=now, tell=tell)
    if taken is not None:
        _given([taken], trail)
        if taken.kind == "charge":  # low, it left its work: told, as the local stack tells it
            tell(gone_to_charge(taken, now))
    return {"took": taken.id if taken is not None else None}


def on_tick(
    dispatcher: Dispatcher,
    trail: TrailTable | None = None,
    tell: Callable[[Tidings], None] = _logged_only,
) -> dict[str, Any]:
    """Once a minute: assigned tasks whose robot never acknowledged them are offered again
    or, when they cannot be carried out any more, told as lost (`reoffer`); then queued
    tasks go to robots that are free now. A robot freed while its rule event was lost
    (dead-lettered, or the function failed) would otherwise wait for its next change; with
    no open task this is one read of the open tasks and nothing more. The closed zones are
    told again (retained), so two changes published out of order by two invocations agree
    with the table within a minute. Last, when the fleet's batteries drain, the idle robots
    that are low go to charge (`Dispatcher.charge_low`, the rule `observe` applies to each
    report): the rule selects a robot's update only when it becomes idle or stops, so a
    robot that runs low standing idle, or found every charger taken, is sent from here."""
    dispatcher.announce_closures()
    table, search = dispatcher.store, dispatcher.candidates
    assert isinstance(table, TaskTable) and isinstance(search, FleetSearch)
    watch = watch_assigned(dispatcher, table, search, now=dispatcher.clock(), tell=tell)
    given = list(watch.given)
    if watch.queued:
        with _searching(dispatcher, every=_restricted(watch.queued)):
            given += dispatcher.drain()
    charging: list[Task] = []
    if dispatcher.respect_battery and dispatcher.fleet.batteries_drain:
        charging = dispatcher.charge_low(
            search.low_idle(dispatcher.fleet.battery_plan.charge_below)
        )
    _given(given + charging, trail)
    for task in charging:
        tell(gone_to_charge(task, dispatcher.clock()))
    return {
        "given": [task.id for task in given],
        "offered_again": watch.offered_again,
        "acknowledged": watch.acknowledged,
        "closed": watch.closed,
        "lost": [lost.task for lost in watch.lost],
        "charging": [task.id for task in charging],
    }


def _given(tasks: list[Task], trail: TrailTable | None) -> None:
    """Log and record the tasks the dispatcher gave robots by itself."""
    for task in tasks:
        log.info("task %s (%s to %s) given to %s", task.id, task.kind, task.zone, task.thing)
        if trail is not None:
            trail.record(task_given(task))


def on_request(
    request: SkillRequest, dispatcher: Dispatcher, trail: TrailTable | None = None
) -> Answer:
    if isinstance(request, Submit):
        order = request.order
        # "Every idle robot" needs them all; a group's members and the robots in a zone may
        # be on any page of idle robots.
        every = order.idle or order.group is not None or order.origin is not None
        try:
            with _searching(dispatcher, every=every):
                return Answer(200, dispatcher.submit(order))
        except DispatchError as err:
            raise BadRequest(str(err), error=err.code) from err
    if isinstance(request, ListTasks):
        return Answer(
            200,
            {
                "tasks": dispatcher.tasks(),
                "closed": dispatcher.closed_zones(),
                "out_of_service": out_of_service(dispatcher),
            },
        )
    if isinstance(request, ListOutOfService):
        return Answer(200, {"out_of_service": out_of_service(dispatcher)})
    if isinstance(request, SetService | Charge):
        return _on_robot(request, dispatcher, trail)
    if isinstance(request, ListPending):
        return Answer(200, {"tasks": dispatcher.pending()})
    if isinstance(request, ListClosed):
        return Answer(200, {"closed": dispatcher.closed_zones()})
    if isinstance(request, SetZone):
        try:
            # Opened, the queued tasks that waited for it go: read every page if one of them
            # is only some robots' to take.
            every = not request.closed and _restricted(dispatcher.pending())
            with _searching(dispatcher, every=every):
                return Answer(200, dispatcher.set_zone(request.zone, closed=request.closed))
        except DispatchError as err:
            raise BadRequest(str(err), error=err.code) from err
    assert isinstance(request, Cancel)
    cancelled = dispatcher.cancel(request.task_id)
    if cancelled is None:
        raise BadRequest(f"no open task {request.task_id!r}", status=404)
    return Answer(200, {"task": cancelled})


def _on_robot(
    request: SetService | Charge, dispatcher: Dispatcher, trail: TrailTable | None
) -> Answer:
    """A robot out of service or back, or sent to charge now: the local host's
    `/vahr/service/{thing}` and `/vahr/charge/{thing}`, with their answers and refusals."""
    thing = request.thing
    if thing not in dispatcher.fleet.robot_things:
        raise BadRequest(
            f"{thing[:40]} is not a robot of the fleet", status=404, error="unknown_robot"
        )
    # A task given back to the queue (or waiting for a robot back) may be only some
    # robots' to take: read every page then.
    with _searching(dispatcher, every=_restricted(dispatcher.pending())):
        if isinstance(request, Charge):
            try:
                task = dispatcher.charge(thing, asked=True)
            except DispatchError as err:
                raise BadRequest(str(err), error=err.code) from err
            return Answer(200, {"task": task})
        change = set_in_service(dispatcher, thing, request.in_service)
    given = change.given + [task for task in change.reassigned if task.thing is not None]
    _given(given, trail)
    return Answer(200, change)


def _restricted(tasks: list[Task]) -> bool:
    """Whether a task among these is only some robots' (a group's member, a robot in a
    zone): such a robot may be on any page of idle robots."""
    return any(task.robots for task in tasks)


def _searching(dispatcher: Dispatcher, *, every: bool) -> AbstractContextManager[None]:
    """Within it, the fleet search reads every page (`every`) or asks for idle robots first."""
    search = dispatcher.candidates
    if every and isinstance(search, FleetSearch):
        return search.every_robot()
    return nullcontext()


def _request(event: dict[str, Any]) -> SkillRequest:
    operation = event.get("operation")
    if operation not in OPERATIONS:
        raise BadRequest(
            f"operation: {str(operation)[:40]!r} is not one of {', '.join(OPERATIONS)}"
        )
    try:
        return msgspec.convert(event, SkillRequest)  # type: ignore[arg-type]
    except msgspec.ValidationError as err:
        raise BadRequest(str(from_validation_error(err))) from err
