"""Fleet dispatch: tasks without a robot's name, given to the best free robot or queued.

One dispatcher, two hosts. This module is the pure core both run: the `Task` model, the
documented cost, the ranking, and a `Dispatcher` that reaches the world only through three
ports, so the local stack (SQLite, the local fleet index, the local broker) and AWS
(DynamoDB, IoT fleet indexing, iot-data) run the same decisions.

The cost of giving a task to a robot (docs/dispatch.md): the length of the path from the
robot's reported pose to the task's pickup zone and from there to its drop zone, on the
floor's geometry from fleet.yaml. VAHR's robots drive straight from anywhere to anywhere
(the simulator does, and walls are drawn, not driven around: `fleet._check_reachable`), so
the default path length is the straight line; a host with a planner passes its own
`path_length`. Robots that are idle rank before robots that are busy with work the
dispatcher did not give them (a command by name), whatever the distance; equal costs are
broken by thing name, so the same state always picks the same robot.

A person's request is an `Order`; the dispatcher turns it into one `Task` per robot it needs
(two for "send two robots", one per member for a group), so that a task is only ever held
by one robot and "two robots never take one task" is one conditional write in the store.
This module imports only msgspec and the rest of `vahr.protocol`: the Lambda bundle carries it.
"""

from __future__ import annotations

import heapq
import math
import uuid
from collections.abc import Callable, Iterable
from datetime import UTC, datetime, timedelta
from typing import Literal, Protocol

import msgspec

from vahr.domain.fleet import FLEET_GROUP, Fleet, Pose
from vahr.protocol.messages import Command, new_command

TaskKind = Literal["navigate", "deliver"]
TaskStatus = Literal["queued", "assigned", "done", "cancelled"]
# What a finished task ended as: the robot's result for its command, or why it ended early.
Outcome = Literal["done", "failed", "cancelled", "rejected", "preempted"]

# The zone every delivery picks its package up at (the arm at the conveyor, DESIGN.md).
PICKUP_ZONE = "LOADING"
# Statuses of a robot with nothing to do: ranked before every busy one.
IDLE_STATUSES = frozenset({"idle", "stopped"})
# Statuses of a robot at work on something the dispatcher did not give it: it may be given
# a task (which preempts that work, as any new motion command does) but only after every
# idle robot. Any other status (stuck, error) or a disconnected robot is never a candidate.
BUSY_STATUSES = frozenset({"navigating", "loading", "unloading", "waiting"})
# A command's result that ends the task it carried.
FINAL_RESULTS = frozenset({"done", "failed", "cancelled", "rejected"})
# The `source` of every command the dispatcher publishes.
SOURCE = "dispatcher"


class DispatchError(ValueError):
    """An order that cannot be carried out as asked: an unknown zone or group, a count the
    fleet cannot meet. `str(error)` is one line a person can act on; nothing was changed."""


class Task(msgspec.Struct, frozen=True, kw_only=True):
    """One robot's share of an order, as the store keeps it and `GET /vahr/tasks` shows it.

    `id` is also the id of the command published for it (so republishing after a restart is
    executed once, DESIGN.md). `robots` lists the only robots that may take it (a group's
    member, a robot in a named zone); empty means any. `created_at` (RFC 3339 UTC with
    microseconds) then `id` order the queue. `version` grows by one on every write; stores
    use it for their conditional writes.
    """

    id: str
    request: str
    kind: TaskKind
    zone: str
    pickup: str | None = None
    group: str | None = None
    robots: list[str] = []
    status: TaskStatus = "queued"
    thing: str | None = None
    created_at: str
    assigned_at: str | None = None
    outcome: Outcome | None = None
    version: int = 1

    @property
    def order_key(self) -> tuple[str, str]:
        """The queue's order: first come, first served; `id` breaks a tie."""
        return (self.created_at, self.id)

    def allows(self, thing: str) -> bool:
        return not self.robots or thing in self.robots


class Order(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """What a person asked for, the body of `POST {api}/vahr/tasks` and the skill's submit.

    - `count` robots of any (or of `group`'s members when `group` is given and `count` is
      set) go to `zone`: "send two robots to zone B".
    - `group` alone: every member of the group goes, each its own task; a busy member's
      task waits for that member: "send the waders to the shop".
    - `origin`: the free robots reported in that zone now go; nothing is queued: "send the
      robots in zone A to the loading zone".
    - `idle`: every idle robot now goes; nothing is queued: "every idle robot to zone C".
    """

    kind: TaskKind = "navigate"
    zone: str
    count: int | None = None
    group: str | None = None
    origin: str | None = None
    idle: bool = False


class RobotState(msgspec.Struct, frozen=True, kw_only=True):
    """What the dispatcher needs to know of one robot, from a fleet index (or its shadow)."""

    thing: str
    status: str
    connected: bool = True
    zone: str | None = None
    pose: Pose | None = None
    last_command_id: str | None = None
    last_result: str | None = None

    @property
    def available(self) -> bool:
        """Connected and idle or busy; a stuck, failed or offline robot takes no task."""
        return self.connected and (self.status in IDLE_STATUSES or self.status in BUSY_STATUSES)

    @property
    def idle(self) -> bool:
        return self.status in IDLE_STATUSES


class Submission(msgspec.Struct, frozen=True, kw_only=True):
    """What became of an order: the tasks given to a robot now and those queued, with each
    queued task's place in line (1 is next), as `POST /vahr/tasks` answers it."""

    request: str
    assigned: list[Task] = []
    queued: list[Task] = []
    positions: list[int] = []


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
# The length of the path between two poses on the floor, in metres.
PathLength = Callable[[Pose, Pose], float]


def straight_line(start: Pose, end: Pose) -> float:
    """The path length on VAHR's floors: robots drive straight, walls are not obstacles."""
    return math.hypot(end.x - start.x, end.y - start.y)


def task_cost(
    fleet: Fleet, pose: Pose, task: Task, path_length: PathLength = straight_line
) -> float:
    """Metres a robot at `pose` drives to do `task`: to the pickup (if any), then to the
    drop zone. A robot already in the drop zone of a navigation costs nothing."""
    drop = fleet.zone(task.zone).pose
    if task.pickup is None:
        return path_length(pose, drop)
    pickup = fleet.zone(task.pickup).pose
    return path_length(pose, pickup) + path_length(pickup, drop)


def robot_pose(fleet: Fleet, state: RobotState) -> Pose:
    """Where a robot is: its reported pose, else its reported zone's, else its start."""
    if state.pose is not None:
        return state.pose
    if state.zone is not None and state.zone in fleet.zone_ids:
        return fleet.zone(state.zone).pose
    try:
        return fleet.robot(state.thing).start
    except KeyError:
        return Pose(0.0, 0.0)


def rank(
    fleet: Fleet,
    task: Task,
    robots: Iterable[RobotState],
    *,
    limit: int | None = None,
    path_length: PathLength = straight_line,
) -> list[RobotState]:
    """The robots allowed to take `task`, best first: idle before busy, then by cost, then
    by thing name. With `limit`, only the best `limit` (a partial sort: 10,000 robots are
    ranked without sorting them all).

    The cost is `task_cost`, computed here with the pickup and drop looked up once: the
    leg from the pickup to the drop is the same for every robot.
    """
    drop = fleet.zone(task.zone).pose
    pickup = fleet.zone(task.pickup).pose if task.pickup is not None else None
    first = pickup or drop
    rest = path_length(pickup, drop) if pickup is not None else 0.0
    allowed = frozenset(task.robots)
    hypot, fx, fy = math.hypot, first.x, first.y
    straight = path_length is straight_line
    keyed: list[tuple[bool, float, str, RobotState]] = []
    for robot in robots:
        if allowed and robot.thing not in allowed:
            continue
        pose = robot.pose if robot.pose is not None else robot_pose(fleet, robot)
        to_first = hypot(pose.x - fx, pose.y - fy) if straight else path_length(pose, first)
        # False sorts before True: idle robots first.
        keyed.append((robot.status not in IDLE_STATUSES, to_first + rest, robot.thing, robot))
    # Tuples compare field by field and thing names are unique, so the states themselves
    # are never compared.
    if limit is None:
        keyed.sort()
    elif limit == 1:
        keyed = [min(keyed)] if keyed else []
    else:
        keyed = heapq.nsmallest(limit, keyed)
    return [entry[3] for entry in keyed]


def timestamp(moment: datetime) -> str:
    """RFC 3339 UTC with microseconds: sorts as text in time order."""
    return moment.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


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
        path_length: PathLength = straight_line,
    ) -> None:
        self.fleet = fleet
        self.store = store
        self.candidates = candidates
        self.publish = publish
        self.clock = clock
        self.path_length = path_length
        self._acknowledged: set[str] = set()

    # --- orders -------------------------------------------------------------------------

    def submit(self, order: Order) -> Submission:
        """Check `order`, store its tasks and give each to the best free robot now; what no
        robot can take now stays queued. Raises DispatchError (nothing stored) when the
        order names an unknown zone or group or asks for more robots than it may have."""
        tasks = self._tasks_for(order)
        for task in tasks:
            self.store.add(task)
        assigned: list[Task] = []
        queued: list[Task] = []
        for task in tasks:
            taken = self._give(task)
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

    def tasks(self) -> list[Task]:
        """What the station shows: the tasks robots hold, then the queue."""
        return self.store.active() + self.store.pending()

    # --- robots -------------------------------------------------------------------------

    def observe(self, state: RobotState) -> Task | None:
        """A robot reported its state: if that ends its task, record how, and if it is
        free, give it the first queued task it may take. Returns the task it took."""
        held = self._held_by(state.thing)
        if held is not None:
            if state.last_command_id == held.id:
                self._acknowledged.add(held.id)
                if state.last_result not in FINAL_RESULTS:
                    return None
                self.store.finish(held.id, outcome=state.last_result)  # type: ignore[arg-type]
            elif held.id in self._acknowledged:
                # The robot took our command and now reports another: someone gave it a
                # command by name, which preempted the task. (Before the acknowledgment, an
                # older command's update may still be on its way: that is no preemption.)
                self.store.finish(held.id, outcome="preempted")
            else:
                return None
            self._acknowledged.discard(held.id)
        if not state.available:
            return None
        return self.robot_freed(state.thing)

    def robot_freed(self, thing: str) -> Task | None:
        """Give `thing` the first queued task it may take (first come, first served). When
        another dispatcher got there first, the next one; None when nothing is left."""
        for task in self.store.pending():
            if not task.allows(thing):
                continue
            taken = self._assign(task, thing)
            if taken is not None:
                return taken
            if self._held_by(thing) is not None:
                return None  # the robot itself was taken meanwhile
        return None

    def drain(self) -> list[Task]:
        """Give every queued task that a free robot may take to the best such robot (at
        start-up, after a restart, when a robot comes back online)."""
        given = []
        for task in self.store.pending():
            taken = self._give(task)
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
        return new_command(task.kind, {"zone": task.zone}, source=SOURCE, command_id=task.id)

    # --- inside -------------------------------------------------------------------------

    def _tasks_for(self, order: Order) -> list[Task]:
        fleet = self.fleet
        if order.zone not in fleet.zone_ids:
            raise DispatchError(
                f"there is no zone {order.zone!r}; zones are {', '.join(fleet.zone_ids)}"
            )
        if order.origin is not None and order.origin not in fleet.zone_ids:
            raise DispatchError(
                f"there is no zone {order.origin!r}; zones are {', '.join(fleet.zone_ids)}"
            )
        if order.count is not None and order.count < 1:
            raise DispatchError("count: at least one robot is needed")
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
            raise DispatchError(f"no robot{where} is free to go now")
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
        raise DispatchError(f"there is no group {group_id!r}; groups are {', '.join(known)}")

    @staticmethod
    def _check_count(count: int, most: int, what: str) -> None:
        if count > most:
            robots = "robot" if most == 1 else "robots"
            raise DispatchError(f"{what} has {most} {robots}; {count} cannot go")

    def _free(self, *, zone: str | None = None, idle: bool = False) -> list[RobotState]:
        """Available robots that hold no task (in the candidates' order)."""
        holding = {task.thing for task in self.store.active()}
        robots = self.candidates.available(zone=zone)
        # `RobotState.available` and `.idle` spelled out: this runs for every robot.
        takes = IDLE_STATUSES if idle else IDLE_STATUSES | BUSY_STATUSES
        return [
            robot
            for robot in robots
            if robot.connected and robot.status in takes and robot.thing not in holding
        ]

    def _give(self, task: Task) -> Task | None:
        """Assign `task` to the best free robot that will take it, trying the next when a
        race is lost; None when no free robot may take it."""
        free = self._free()
        for robot in rank(self.fleet, task, free, path_length=self.path_length):
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

    def _held_by(self, thing: str) -> Task | None:
        for task in self.store.active():
            if task.thing == thing:
                return task
        return None
