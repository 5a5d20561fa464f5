"""The dispatcher both hosts run (`vahr up`'s and the dispatcher Lambda): it gives tasks
to robots and reaches the world only through three ports, so the local stack (SQLite, the
local fleet index, the local broker) and AWS (DynamoDB, IoT fleet indexing, iot-data) make
the same decisions.

A person's request is an `Order`; the dispatcher turns it into one `Task` per robot it needs
(two for "send two robots", one per member for a group), so that a task is only ever held
by one robot and "two robots never take one task" is one conditional write in the store.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING, Protocol

import msgspec

from vahr.dispatch.energy import EnergyRule
from vahr.dispatch.ranking import (
    BUSY_STATUSES,
    IDLE_STATUSES,
    STRAIGHT,
    RobotState,
    Routes,
    rank,
    robot_pose,
)
from vahr.dispatch.tasks import (
    FINAL_RESULTS,
    PICKUP_ZONE,
    SOURCE,
    DispatchError,
    Order,
    Outcome,
    Submission,
    Task,
    timestamp,
)
from vahr.domain.fleet import FLEET_GROUP
from vahr.protocol.messages import Command, ZoneClosures, new_command

if TYPE_CHECKING:
    from vahr.domain.fleet import Fleet, Zone


class TaskStore(Protocol):
    """Where tasks live, shared by every dispatcher process (SQLite locally, DynamoDB on AWS).

    Every method is one atomic operation; the conditional ones return None instead of
    raising when their condition does not hold, so a race lost is an ordinary answer.
    """

    def add(self, task: Task) -> None:
        """Store a new task (status `queued`). Its id is new; a second add of it may fail."""
        ...

    def assign(self, task_id: str, thing: str, *, at: str) -> Task | None:
        """In one transaction: if the task is `queued` and `thing` holds no `assigned` task,
        set status `assigned`, `thing`, `assigned_at` = `at`, version + 1, and return the
        task as stored; otherwise change nothing and return None. This is the one place
        that keeps two robots from taking one task and one robot from taking two."""
        ...

    def release(self, task_id: str) -> Task | None:
        """An `assigned` task back to `queued` (its command could not be sent), keeping its
        place in the queue (`created_at` unchanged), `thing` cleared, version + 1. None if
        the task is not assigned."""
        ...

    def finish(self, task_id: str, *, outcome: Outcome) -> Task | None:
        """An `assigned` task ends: status `done` when `outcome` is "done", else
        `cancelled`; `outcome` recorded, version + 1. None if the task is not assigned."""
        ...

    def cancel(self, task_id: str) -> Task | None:
        """A `queued` or `assigned` task is cancelled (outcome "cancelled"), version + 1,
        and returned as it was before (so the caller can stop its robot). None if the task
        is unknown or already over."""
        ...

    def get(self, task_id: str) -> Task | None:
        """The task with this id, whatever its status."""
        ...

    def pending(self) -> list[Task]:
        """Every `queued` task in queue order (`Task.order_key`)."""
        ...

    def active(self) -> list[Task]:
        """Every `assigned` task, oldest first."""
        ...

    def close_zone(self, zone: str, *, at: str) -> bool:
        """Record `zone` closed (since `at`); False when it was closed already."""
        ...

    def open_zone(self, zone: str) -> bool:
        """Record `zone` open again; False when it was not closed."""
        ...

    def closed_zones(self) -> list[str]:
        """The zones closed now, sorted."""
        ...


class Candidates(Protocol):
    """The robots as a fleet index knows them (the local index; IoT fleet indexing)."""

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        """Every connected robot that is idle or busy (`RobotState.available`), only those
        reported in `zone` when it is given. Robots holding a task are included: the
        dispatcher leaves them out itself."""
        ...

    def state(self, thing: str) -> RobotState | None:
        """One robot's state, whatever it is; None for a robot the index does not know."""
        ...


# Sends a command to one robot: (thing, command). The local host publishes on the broker,
# AWS through iot-data. It raises on failure; the dispatcher then gives the task back.
Publish = Callable[[str, Command], None]
# Tells every robot which zones are closed now: the retained `ZoneClosures` on
# `vahr/fleet/zones` (the local broker, or iot-data with retain on AWS).
PublishClosures = Callable[[ZoneClosures], None]
# The path lengths on the fleet's floor with these zones closed (`ranking.Routes`).
RoutesFor = Callable[[frozenset[str]], Routes]


class ZoneChange(msgspec.Struct, frozen=True, kw_only=True):
    """What closing or opening a zone did, as `POST /vahr/zones/{zone}` answers it:
    `changed` is False when the zone already was so; `waiting` lists the queued tasks that
    wait for the zone to open (after closing) or that went now (after opening: `given`)."""

    zone: str
    closed: bool
    changed: bool
    waiting: list[Task] = []
    given: list[Task] = []


class ServiceChange(msgspec.Struct, frozen=True, kw_only=True):
    """What taking a robot out of service (or putting it back) did: `changed` is False
    when it already was so; `reassigned` the task it held, back in the queue (and given to
    another robot when one may take it: `thing` then names that robot); `waiting` the queued
    tasks only it may take, which wait for it; `given` the task it took once back."""

    thing: str
    in_service: bool
    changed: bool
    reassigned: list[Task] = []
    waiting: list[Task] = []
    given: list[Task] = []


class Dispatcher:
    """Gives tasks to robots through the three ports; holds no state of its own.

    Any number of dispatchers may share one store: every assignment is the store's
    conditional `assign`, and a dispatcher that loses a race tries its next choice.
    `clock` returns the current time (injected so tests can order tasks). The only thing
    it remembers is which tasks it has seen their robot acknowledge (see `observe`).
    """

    def __init__(
        self,
        *,
        fleet: Fleet,
        store: TaskStore,
        candidates: Candidates,
        publish: Publish,
        clock: Callable[[], datetime] = lambda: datetime.now(UTC),
        routes: RoutesFor | None = None,
        publish_closures: PublishClosures | None = None,
        on_given_up: Callable[[Task], None] | None = None,
        on_charging: Callable[[Task], None] | None = None,
        respect_battery: bool = True,
    ) -> None:
        """`routes` gives the path lengths on the floor for a set of closed zones (default:
        straight lines, a drawn floor); `publish_closures` tells the robots which zones are
        closed after every change; `on_given_up` is told each task the fleet gives up without
        being asked (its robot was sent elsewhere by name), so that it is announced: no task
        leaves the fleet's hands without a word; `on_charging` each robot the dispatcher
        sends to charge by itself (it is low), so that it is announced too.
        `respect_battery=False` ignores the batteries (what a fleet without the energy rule
        would do; the shift benchmark compares the two)."""
        self.fleet = fleet
        self.on_given_up = on_given_up
        self.on_charging = on_charging
        self.respect_battery = respect_battery
        self.store = store
        self.candidates = candidates
        self.publish = publish
        self.clock = clock
        self.routes_for: RoutesFor = routes or (lambda closed: STRAIGHT)
        self.publish_closures = publish_closures
        self._acknowledged: set[str] = set()

    # --- orders -------------------------------------------------------------------------

    def submit(self, order: Order) -> Submission:
        """Check `order`, store its tasks and give each to the best free robot now; what no
        robot can take now stays queued. Raises DispatchError (nothing stored) when the
        order names an unknown zone or group or asks for more robots than it may have."""
        tasks = self._tasks_for(order)
        closed = self._closed()
        for zone in (order.zone, tasks[0].pickup):
            if zone is not None and zone in closed:
                raise DispatchError("zone_closed", f"zone {zone} is closed; no robot is sent there")
        for task in tasks:
            self.store.add(task)
        assigned: list[Task] = []
        queued: list[Task] = []
        for task in tasks:
            taken = self._give(task, closed)
            if taken is None:
                queued.append(task)
            else:
                assigned.append(taken)
        queue = [task.id for task in self.store.pending()]
        positions = [queue.index(task.id) + 1 for task in queued if task.id in queue]
        return Submission(
            request=tasks[0].request, assigned=assigned, queued=queued, positions=positions
        )

    def cancel(self, task_id: str) -> Task | None:
        """Cancel a queued or assigned task; a robot on it is told to stop. None when no
        such task is open."""
        before = self.store.cancel(task_id)
        if before is not None and before.status == "assigned" and before.thing is not None:
            stop = new_command("stop", source=SOURCE)
            self.publish(before.thing, stop)
            self.robot_freed(before.thing)
        return before

    def pending(self) -> list[Task]:
        """The queue, next first."""
        return self.store.pending()

    # --- zones --------------------------------------------------------------------------

    def closed_zones(self) -> list[str]:
        """The zones closed now, sorted."""
        return self.store.closed_zones()

    def set_zone(self, zone: str, *, closed: bool) -> ZoneChange:
        """Close or open `zone`. Closed: no task goes there (orders to it are refused, queued
        ones wait), robots are told (they leave it and drive around its area), and a task
        whose robot then gives it up waits in the queue again. Opened: robots are told and
        the queued tasks that waited go to free robots. DispatchError for an unknown zone."""
        if zone not in self.fleet.zone_ids:
            raise DispatchError(
                "unknown_zone",
                f"there is no zone {zone!r}; zones are {', '.join(self.fleet.zone_ids)}",
            )
        at = timestamp(self.clock())
        changed = self.store.close_zone(zone, at=at) if closed else self.store.open_zone(zone)
        now_closed = self.store.closed_zones()
        self.announce_closures(now_closed)
        if closed:
            waiting = [task for task in self.store.pending() if zone in (task.zone, task.pickup)]
            return ZoneChange(zone=zone, closed=True, changed=changed, waiting=waiting)
        given = [task for task in self.drain() if zone in (task.zone, task.pickup)]
        waiting = [
            task
            for task in self.store.pending()
            if zone in (task.zone, task.pickup) and not self._blocked(task, set(now_closed))
        ]
        return ZoneChange(zone=zone, closed=False, changed=changed, waiting=waiting, given=given)

    def announce_closures(self, closed: list[str] | None = None) -> None:
        """Tell the robots which zones are closed now (after a change, at start-up, and on
        AWS once a minute, so a robot never keeps a closure that was lifted)."""
        if self.publish_closures is None:
            return
        zones = self.store.closed_zones() if closed is None else closed
        self.publish_closures(ZoneClosures(closed=sorted(zones), at=self.clock()))

    def tasks(self) -> list[Task]:
        """What the station shows: the tasks robots hold, then the queue."""
        return self.store.active() + self.store.pending()

    # --- robots -------------------------------------------------------------------------

    def observe(self, state: RobotState) -> Task | None:
        """A robot reported its state: if that ends its task, record how, and if it is
        free, give it the first queued task it may take. Returns the task it took."""
        held = self._held_by(state.thing)
        if held is not None and held.kind == "charge":
            if not self._charge_over(held, state):
                return None
        elif held is not None:
            if state.last_command_id == held.id:
                self._acknowledged.add(held.id)
                if state.last_result not in FINAL_RESULTS:
                    return None
                if state.last_result in ("failed", "rejected") and self._blocked(held):
                    # The robot gave it up because its zone closed: it waits for the zone.
                    self.store.release(held.id)
                else:
                    self.store.finish(held.id, outcome=state.last_result)  # type: ignore[arg-type]
            elif held.id in self._acknowledged:
                # The robot took our command and now reports another: someone gave it a
                # command by name, which preempted the task. (Before the acknowledgment, an
                # older command's update may still be on its way: that is no preemption.)
                given_up = self.store.finish(held.id, outcome="preempted")
                if given_up is not None and self.on_given_up is not None:
                    self.on_given_up(given_up)
            else:
                return None
            self._acknowledged.discard(held.id)
        if not state.available:
            return None
        energy = self._energy()
        if energy is not None and energy.wants_charge(state) and state.idle:
            return self.charge(state.thing, state=state)
        return self.robot_freed(state.thing, state)

    def robot_freed(self, thing: str, state: RobotState | None = None) -> Task | None:
        """Give `thing` the first queued task it may take (first come, first served): not
        one into a closed zone, nor, on a map, one it has no path to. When another
        dispatcher got there first, the next one; None when nothing is left."""
        pending = self.store.pending()
        if not pending:
            return None
        closed = self._closed()
        on_map = self.fleet.floor is not None and self.fleet.floor.map is not None
        energy = self._energy(closed)
        # Its state as reported (passed by `observe`): a robot out of service takes nothing.
        state = state or self.candidates.state(thing)
        if state is not None and not state.in_service:
            return None
        for task in pending:
            if not task.allows(thing) or self._blocked(task, closed):
                continue
            if (
                state is not None
                and (on_map or energy is not None)
                and not rank(
                    self.fleet,
                    task,
                    [state],
                    limit=1,
                    routes=self.routes_for(closed),
                    energy=energy,
                )
            ):
                continue
            taken = self._assign(task, thing)
            if taken is not None:
                return taken
            if self._held_by(thing) is not None:
                return None  # the robot itself was taken meanwhile
        return None

    def drain(self) -> list[Task]:
        """Give every queued task that a free robot may take to the best such robot (at
        start-up, after a restart, when a robot comes back online, when a zone opens)."""
        pending = self.store.pending()
        if not pending:
            return []
        given = []
        closed = self._closed()
        for task in pending:
            if self._blocked(task, closed):
                continue
            taken = self._give(task, closed)
            if taken is not None:
                given.append(taken)
        return given

    def resume(self) -> list[Task]:
        """After a restart: every assigned task whose robot never acknowledged its command
        is sent again (the same id, so a robot that had it runs it once), and a task whose
        robot already finished it is closed. Returns the tasks sent again."""
        sent = []
        for task in self.store.active():
            assert task.thing is not None
            state = self.candidates.state(task.thing)
            if state is not None and state.last_command_id == task.id:
                if state.last_result in FINAL_RESULTS:
                    self.store.finish(task.id, outcome=state.last_result)  # type: ignore[arg-type]
                continue
            try:
                self.publish(task.thing, self.command_for(task))
            except Exception:  # noqa: BLE001 - the robot is unreachable: the task waits again
                self.store.release(task.id)
                continue
            sent.append(task)
        return sent

    @staticmethod
    def command_for(task: Task) -> Command:
        """The command that carries out `task`; its id is the task's."""
        # A robot goes to charge by driving to the charger; it charges standing there.
        action = "navigate" if task.kind == "charge" else task.kind
        return new_command(action, {"zone": task.zone}, source=SOURCE, command_id=task.id)

    # --- batteries ----------------------------------------------------------------------

    def charge(
        self, thing: str, *, state: RobotState | None = None, asked: bool = False
    ) -> Task | None:
        """Send `thing` to the nearest free charger, holding it (a `charge` task) until the
        robot is charged. By itself (`asked` False: the robot is low and idle) it is
        announced (`on_charging`) and None means no charger is free now (the robot asks
        again with its next report); asked ("send X to charge"), a task it holds goes back
        to the queue first, and DispatchError says why it cannot go."""
        if thing not in self.fleet.robot_things:
            raise DispatchError("unknown_robot", f"there is no robot {thing!r}")
        state = state or self.candidates.state(thing)
        if state is None or not state.connected:
            if asked:
                raise DispatchError("none_free", f"{thing} is offline")
            return None
        if not state.in_service:
            if asked:
                raise DispatchError("out_of_service", f"{thing} is out of service")
            return None
        held = self._held_by(thing)
        if held is not None and held.kind == "charge":
            return held if asked else None
        closed = self._closed()
        chargers = self._free_chargers(thing, closed)
        if not chargers:
            if asked:
                raise DispatchError("no_charger", "every charger is taken or closed now")
            return None
        routes = self.routes_for(closed)
        here = robot_pose(self.fleet, state)
        chargers.sort(key=lambda zone: (routes.field(zone).distance(here.x, here.y), zone.id))
        if held is not None:
            if not asked:
                return None
            self.store.release(held.id)
            self._acknowledged.discard(held.id)
        for charger in chargers:
            task = self._hold_charger(thing, charger.id)
            if task is None:
                continue
            if not asked and self.on_charging is not None:
                self.on_charging(task)
            if held is not None:
                self.drain()
            return task
        if held is not None:
            self.drain()
        if asked:
            raise DispatchError("no_charger", "every charger is taken or closed now")
        return None

    def usable(self, robot: RobotState) -> bool:
        """Whether the dispatcher would give `robot` a task at all now: in service and, when
        batteries count, not so low that it must charge first (`EnergyRule.takes_tasks`).
        A fleet search that stops at its first page holding a free robot reads past the
        robots that are not (the dispatcher Lambda's)."""
        if not robot.in_service:
            return False
        if not self.respect_battery or not self.fleet.batteries_drain:
            return True
        return EnergyRule(self.fleet, STRAIGHT).takes_tasks(robot)

    def charge_low(self, robots: list[RobotState]) -> list[Task]:
        """Send each of `robots` that is idle, in service, holds no task and is low
        (`EnergyRule.wants_charge`) to charge, as `observe` does with a robot's report:
        for a host that does not see every report (the dispatcher Lambda's schedule).
        Returns the charge tasks given; a robot with no charger free now is left alone."""
        energy = self._energy()
        if energy is None:
            return []
        holding = {task.thing for task in self.store.active()}
        given = []
        for robot in robots:
            if not (robot.idle and robot.in_service and energy.wants_charge(robot)):
                continue
            if robot.thing in holding:
                continue
            task = self.charge(robot.thing, state=robot)
            if task is not None:
                given.append(task)
        return given

    def _free_chargers(self, thing: str, closed: frozenset[str]) -> list[Zone]:
        """The chargers no other robot holds (a `charge` task) or stands at, not closed."""
        held = {task.zone for task in self.store.active() if task.kind == "charge"}
        held |= {task.zone for task in self.store.pending() if task.kind == "charge"}
        free = []
        for zone in self.fleet.chargers:
            if zone.id in closed or zone.id in held:
                continue
            others = self.candidates.available(zone=zone.id)
            if any(robot.thing != thing for robot in others):
                continue
            free.append(zone)
        return free

    def _hold_charger(self, thing: str, charger: str) -> Task | None:
        """Take `charger` for `thing`: the charge task is stored, then the earliest open
        charge task for that charger keeps it and a later one gives way (so two
        dispatchers racing for one charger agree whoever wrote first), then it is
        assigned and its command sent. None when the charger went to another robot or
        `thing` could not take it."""
        now = self.clock()
        task = Task(
            id=uuid.uuid4().hex,
            request=uuid.uuid4().hex,
            kind="charge",
            zone=charger,
            robots=[thing],
            created_at=timestamp(now),
        )
        self.store.add(task)
        rivals = [
            other
            for other in self.store.active() + self.store.pending()
            if other.kind == "charge" and other.zone == charger and other.id != task.id
        ]
        if any(other.order_key < task.order_key for other in rivals):
            self.store.cancel(task.id)
            return None
        taken = self._assign(task, thing)
        if taken is None:
            self.store.cancel(task.id)
        return taken

    def _charge_over(self, held: Task, state: RobotState) -> bool:
        """Whether the robot's charge task `held` is over (recorded so), after `state`:
        charged at the charger, failed on the way, or the robot sent elsewhere."""
        if state.last_command_id == held.id:
            self._acknowledged.add(held.id)
            if state.last_result not in FINAL_RESULTS:
                return False
            if state.last_result == "done":
                energy = EnergyRule(self.fleet, STRAIGHT)
                if not energy.charged(state):
                    return False
            self.store.finish(held.id, outcome=state.last_result)  # type: ignore[arg-type]
        elif held.id in self._acknowledged:
            # Sent elsewhere by name while going to charge or charging: the charger is free.
            self.store.finish(held.id, outcome="preempted")
        else:
            return False
        self._acknowledged.discard(held.id)
        return True

    # --- service ------------------------------------------------------------------------

    def service_kept(self, thing: str, in_service: bool) -> ServiceChange:
        """`thing` was already in (or out of) service: nothing changed; out of service, the
        queued tasks that wait for it alone."""
        waiting = [task for task in self.pending() if task.robots == [thing]]
        return ServiceChange(
            thing=thing, in_service=in_service, changed=False, waiting=[] if in_service else waiting
        )

    def withdrawn(self, thing: str) -> ServiceChange:
        """`thing` was just taken out of service (the host records it, and its candidates
        say so from now on): the task it holds goes back to the queue, in its place, and to
        another robot that may take it, and the robot is told to stop; queued tasks only it
        may take wait for it."""
        reassigned: list[Task] = []
        held = self._held_by(thing)
        if held is not None:
            self._acknowledged.discard(held.id)
            if held.kind == "charge":
                self.store.finish(held.id, outcome="cancelled")
            else:
                released = self.store.release(held.id)
                if released is not None:
                    reassigned.append(released)
            self.publish(thing, new_command("stop", source=SOURCE))
            given = {task.id: task for task in self.drain()}
            reassigned = [given.get(task.id, task) for task in reassigned]
        waiting = [task for task in self.store.pending() if task.robots == [thing]]
        return ServiceChange(
            thing=thing, in_service=False, changed=True, reassigned=reassigned, waiting=waiting
        )

    def reinstated(self, thing: str) -> ServiceChange:
        """`thing` is back in service (the host records it): it takes the first queued
        task it may, now."""
        given = self.robot_freed(thing)
        return ServiceChange(
            thing=thing, in_service=True, changed=True, given=[given] if given else []
        )

    # --- inside -------------------------------------------------------------------------

    def _tasks_for(self, order: Order) -> list[Task]:
        fleet = self.fleet
        if order.zone not in fleet.zone_ids:
            raise DispatchError(
                "unknown_zone",
                f"there is no zone {order.zone!r}; zones are {', '.join(fleet.zone_ids)}",
            )
        if order.origin is not None and order.origin not in fleet.zone_ids:
            raise DispatchError(
                "unknown_zone",
                f"there is no zone {order.origin!r}; zones are {', '.join(fleet.zone_ids)}",
            )
        if order.count is not None and order.count < 1:
            raise DispatchError("bad_count", "count: at least one robot is needed")
        members: list[list[str]]
        if order.group is not None:
            group = self._group(order.group)
            if order.count is None:
                members = [[thing] for thing in group]
            else:
                self._check_count(order.count, len(group), f"the group {order.group}")
                members = [list(group)] * order.count
        elif order.origin is not None or order.idle:
            free = self._free(zone=order.origin, idle=order.idle)
            members = [[thing] for thing in sorted(robot.thing for robot in free)]
        else:
            count = 1 if order.count is None else order.count
            self._check_count(count, len(fleet.robots), "the fleet")
            members = [[]] * count
        if not members:
            where = f" in zone {order.origin}" if order.origin else ""
            raise DispatchError("none_free", f"no robot{where} is free to go now")
        request = uuid.uuid4().hex
        now = self.clock()
        pickup = PICKUP_ZONE if order.kind == "deliver" else None
        return [
            Task(
                id=uuid.uuid4().hex,
                request=request,
                kind=order.kind,
                zone=order.zone,
                pickup=pickup,
                group=order.group,
                robots=robots,
                # One microsecond apart, so an order's tasks keep their order in the queue.
                created_at=timestamp(now + timedelta(microseconds=index)),
            )
            for index, robots in enumerate(members)
        ]

    def _group(self, group_id: str) -> list[str]:
        if group_id == FLEET_GROUP:
            return list(self.fleet.robot_things)
        for group in self.fleet.groups:
            if group.id == group_id:
                return list(group.robots)
        known = [group.id for group in self.fleet.groups] or ["none"]
        raise DispatchError(
            "unknown_group", f"there is no group {group_id!r}; groups are {', '.join(known)}"
        )

    @staticmethod
    def _check_count(count: int, most: int, what: str) -> None:
        if count > most:
            robots = "robot" if most == 1 else "robots"
            raise DispatchError("too_many", f"{what} has {most} {robots}; {count} cannot go")

    def _free(self, *, zone: str | None = None, idle: bool = False) -> list[RobotState]:
        """Available robots that hold no task (in the candidates' order)."""
        holding = {task.thing for task in self.store.active()}
        robots = self.candidates.available(zone=zone)
        # `RobotState.available` and `.idle` spelled out: this runs for every robot.
        takes = IDLE_STATUSES if idle else IDLE_STATUSES | BUSY_STATUSES
        return [
            robot
            for robot in robots
            if robot.connected
            and robot.in_service
            and robot.status in takes
            and robot.thing not in holding
        ]

    def _closed(self) -> frozenset[str]:
        return frozenset(self.store.closed_zones())

    def _blocked(self, task: Task, closed: frozenset[str] | set[str] | None = None) -> bool:
        """Whether `task` leads into a closed zone (its drop, or its pickup)."""
        closed = self._closed() if closed is None else closed
        return task.zone in closed or (task.pickup is not None and task.pickup in closed)

    def _give(self, task: Task, closed: frozenset[str] | None = None) -> Task | None:
        """Assign `task` to the best free robot that will take it, trying the next when a
        race is lost; None when no free robot may take it."""
        closed = self._closed() if closed is None else closed
        free = self._free()
        energy = self._energy(closed)
        for robot in rank(self.fleet, task, free, routes=self.routes_for(closed), energy=energy):
            taken = self._assign(task, robot.thing)
            if taken is not None:
                return taken
            current = self.store.get(task.id)
            if current is None or current.status != "queued":
                return None  # another dispatcher gave or cancelled it meanwhile
        return None

    def _assign(self, task: Task, thing: str) -> Task | None:
        taken = self.store.assign(task.id, thing, at=timestamp(self.clock()))
        if taken is None:
            return None
        try:
            self.publish(thing, self.command_for(taken))
        except Exception:  # noqa: BLE001 - unreachable robot: the task keeps its place in line
            self.store.release(taken.id)
            return None
        return taken

    def _energy(self, closed: frozenset[str] | None = None) -> EnergyRule | None:
        """The energy rule on the floor as it is now; None when batteries do not count."""
        if not self.respect_battery or not self.fleet.batteries_drain:
            return None
        closed = self._closed() if closed is None else closed
        return EnergyRule(self.fleet, self.routes_for(closed))

    def _held_by(self, thing: str) -> Task | None:
        for task in self.store.active():
            if task.thing == thing:
                return task
        return None
