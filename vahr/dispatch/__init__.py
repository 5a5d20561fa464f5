"""Fleet task assignment: tasks without a robot's name, given to the best free robot or
queued. One dispatcher, two hosts: `vahr up` (vahr.local.dispatch_host) and the dispatcher
Lambda (lambda/dispatcher) run the same core.

- `tasks`: `Order`, `Task` and the four changes of its state, `Submission`, `DispatchError`
  with its `code`;
- `ranking`: the cost of a robot for a task (`task_cost`), the ranking (`rank`) and the
  path lengths it ranks by (`Routes`, `DistanceField`; `STRAIGHT` on a drawn floor);
- `dispatcher`: the `Dispatcher` and the ports it reaches the world through (`TaskStore`,
  `Candidates`, `Publish`, `PublishClosures`), and what closing a zone did (`ZoneChange`);
- `energy`: whether a robot's battery can do a task and reach a charger after it
  (`EnergyRule`), and when a robot should charge;
- `grid_routes`: path lengths on a map read from the distances `vahr.navigation` wrote
  (the dispatcher Lambda's, which carries no numpy).

It imports the domain and the wire contract only: the Lambda bundle carries it.
"""

from __future__ import annotations

from vahr.dispatch.dispatcher import (
    Candidates,
    Dispatcher,
    Publish,
    PublishClosures,
    RoutesFor,
    ServiceChange,
    TaskStore,
    ZoneChange,
)
from vahr.dispatch.ranking import (
    BUSY_STATUSES,
    IDLE_STATUSES,
    STRAIGHT,
    DistanceField,
    PathLength,
    RobotState,
    Routes,
    StraightLine,
    StraightRoutes,
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
    "STRAIGHT",
    "Candidates",
    "DispatchError",
    "DispatchErrorCode",
    "Dispatcher",
    "DistanceField",
    "Order",
    "Outcome",
    "PathLength",
    "Publish",
    "PublishClosures",
    "RobotState",
    "Routes",
    "RoutesFor",
    "ServiceChange",
    "StraightLine",
    "StraightRoutes",
    "Submission",
    "Task",
    "TaskKind",
    "TaskStatus",
    "TaskStore",
    "ZoneChange",
    "rank",
    "robot_pose",
    "straight_line",
    "task_cost",
    "timestamp",
]
