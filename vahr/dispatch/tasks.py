"""Tasks: what a person ordered (`Order`), one robot's share of it (`Task`, with the four
changes of its state), what became of an order (`Submission`), and why an order was
refused (`DispatchError` and its code)."""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Literal

import msgspec

# `charge`: the dispatcher sends a robot to a charger; the task is held, and the charger
# with it, until the robot is charged (`vahr.dispatch.energy`).
TaskKind = Literal["navigate", "deliver", "charge"]
TaskStatus = Literal["queued", "assigned", "done", "cancelled"]
# What a finished task ended as: the robot's result for its command, or why it ended early.
Outcome = Literal["done", "failed", "cancelled", "rejected", "preempted"]

# The zone every delivery picks its package up at (the arm at the conveyor, docs/protocol.md).
PICKUP_ZONE = "LOADING"
# A command's result that ends the task it carried.
FINAL_RESULTS = frozenset({"done", "failed", "cancelled", "rejected"})
# The `source` of every command the dispatcher publishes.
SOURCE = "dispatcher"


# Why an order cannot be carried out as asked; callers decide on these, never on the text.
DispatchErrorCode = Literal[
    "unknown_zone",
    "unknown_group",
    "bad_count",
    "too_many",
    "none_free",
    "zone_closed",
    "unknown_robot",
    "out_of_service",
    "no_charger",
]


class DispatchError(ValueError):
    """An order that cannot be carried out as asked: an unknown zone or group, a count the
    fleet cannot meet, no robot free to go now, a zone that is closed. `code` says which
    (`DispatchErrorCode`); `str(error)` is one line a person can act on. Nothing was
    changed."""

    def __init__(self, code: DispatchErrorCode, message: str) -> None:
        super().__init__(message)
        self.code: DispatchErrorCode = code


class Task(msgspec.Struct, frozen=True, kw_only=True):
    """One robot's share of an order, as the store keeps it and `GET /vahr/tasks` shows it.

    `id` is also the id of the command published for it (so republishing after a restart is
    executed once, docs/protocol.md). `robots` lists the only robots that may take it (a group's
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

    # Every change of a task's state is one of these four, written here once; a store
    # (SQLite locally, DynamoDB on AWS) checks the condition each names and saves the
    # result, with `version` one higher, over the version it read.

    def assigned(self, thing: str, *, at: str) -> Task:
        """Taken by `thing` at `at` (only a `queued` task may be)."""
        assert self.status == "queued", self.status
        return msgspec.structs.replace(
            self, status="assigned", thing=thing, assigned_at=at, version=self.version + 1
        )

    def released(self) -> Task:
        """Back in the queue, in its old place: its command could not be sent (only an
        `assigned` task may be)."""
        assert self.status == "assigned", self.status
        return msgspec.structs.replace(
            self, status="queued", thing=None, assigned_at=None, version=self.version + 1
        )

    def finished(self, outcome: Outcome) -> Task:
        """Ended with `outcome`: `done` when it is "done", else `cancelled` (only an
        `assigned` task may end)."""
        assert self.status == "assigned", self.status
        return msgspec.structs.replace(
            self,
            status="done" if outcome == "done" else "cancelled",
            outcome=outcome,
            version=self.version + 1,
        )

    def cancelled(self) -> Task:
        """Cancelled by a person (only an open task, `queued` or `assigned`, may be)."""
        assert self.is_open, self.status
        return msgspec.structs.replace(
            self, status="cancelled", outcome="cancelled", version=self.version + 1
        )

    @property
    def is_open(self) -> bool:
        """Queued or assigned: not over yet."""
        return self.status in ("queued", "assigned")


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

    kind: Literal["navigate", "deliver"] = "navigate"
    zone: str
    count: int | None = None
    group: str | None = None
    origin: str | None = None
    idle: bool = False


class Submission(msgspec.Struct, frozen=True, kw_only=True):
    """What became of an order: the tasks given to a robot now and those queued, with each
    queued task's place in line (1 is next), as `POST /vahr/tasks` answers it."""

    request: str
    assigned: list[Task] = []
    queued: list[Task] = []
    positions: list[int] = []


def timestamp(moment: datetime) -> str:
    """RFC 3339 UTC with microseconds: sorts as text in time order."""
    return moment.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
