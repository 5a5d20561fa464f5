"""Fleet task assignment: tasks without a robot's name, given to the best free robot or
queued. One dispatcher, two hosts: `vahr up` (vahr.local.dispatch_host) and the dispatcher
Lambda (lambda/dispatcher) run the same core.

- `tasks`: `Order`, `Task` and the four changes of its state, `Submission`, `DispatchError`
  with its `code`;
- `ranking`: the cost of a robot for a task (`task_cost`) and the ranking (`rank`);
- `dispatcher`: the `Dispatcher` and the three ports it reaches the world through
  (`TaskStore`, `Candidates`, `Publish`).

It imports the domain and the wire contract only: the Lambda bundle carries it.
"""

from __future__ import annotations

from vahr.dispatch.dispatcher import Candidates, Dispatcher, Publish, TaskStore
from vahr.dispatch.ranking import (
    BUSY_STATUSES,
    IDLE_STATUSES,
    PathLength,
    RobotState,
    rank,
    robot_pose,
    straight_line,
    task_cost,
)
from vahr.dispatch.tasks import (
    FINAL_RESULTS,
    PICKUP_ZONE,
    SOURCE,
    DispatchError,
    DispatchErrorCode,
    Order,
    Outcome,
    Submission,
    Task,
    TaskKind,
    TaskStatus,
    timestamp,
)

__all__ = [
    "BUSY_STATUSES",
    "FINAL_RESULTS",
    "IDLE_STATUSES",
    "PICKUP_ZONE",
    "SOURCE",
    "Candidates",
    "DispatchError",
    "DispatchErrorCode",
    "Dispatcher",
    "Order",
    "Outcome",
    "PathLength",
    "Publish",
    "RobotState",
    "Submission",
    "Task",
    "TaskKind",
    "TaskStatus",
    "TaskStore",
    "rank",
    "robot_pose",
    "straight_line",
    "task_cost",
    "timestamp",
]
