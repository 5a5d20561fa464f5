"""What the dispatcher function is invoked with, typed: the skill's requests and the
robots' shadow updates from the topic rule.

The skill invokes it synchronously (`lambda:InvokeFunction`, RequestResponse) with one of

| payload | answer `body` (status 200) |
| --- | --- |
| `{"operation": "submit", "order": {Order}}` | the `Submission`: tasks assigned and queued |
| `{"operation": "tasks"}` | `{"tasks": [...]}`: the tasks robots hold, then the queue |
| `{"operation": "pending"}` | `{"tasks": [...]}`: the queue, next first |
| `{"operation": "cancel", "task_id": "..."}` | `{"task": Task}` as it was before it was cancelled |
| `{"operation": "zones"}` | `{"closed": [zone ids]}` |
| `{"operation": "zone", "zone": "...", "closed": bool}` | the `ZoneChange` |
| `{"operation": "service"}` | `{"out_of_service": [things]}` |
| `{"operation": "set_service", "thing": "...", "in_service": bool}` | the `ServiceChange` |
| `{"operation": "charge", "thing": "..."}` | `{"task": Task}`: the robot's charge task |

and gets `{"status": N, "body": ...}` back: the status and body the local data plane
answers on `{api}/vahr/tasks`, `/vahr/zones`, `/vahr/service` and `/vahr/charge`, so the
skill's two `TaskDesk` adapters read one shape. A request that cannot be carried out is
`{"status": 400 or 404, "body": {"code": N, "message": "one line"}}` (with `error`, the
`DispatchError.code`, when the dispatcher refused it) and changes nothing.

The topic rule (infra/constructs/dispatcher.py) sends `{"thing", "reported"}`:
the robot's whole reported state after an update that left it idle or stopped. An
EventBridge schedule sends its scheduled event once a minute (`is_tick`).
"""

from __future__ import annotations

from typing import Any

import msgspec

# msgspec reads the annotations at run time: Order is needed outside TYPE_CHECKING.
from vahr.dispatch import Order  # noqa: TC001


class Submit(msgspec.Struct, frozen=True, tag_field="operation", tag="submit"):
    order: Order


class ListTasks(msgspec.Struct, frozen=True, tag_field="operation", tag="tasks"):
    pass


class ListPending(msgspec.Struct, frozen=True, tag_field="operation", tag="pending"):
    pass


class Cancel(msgspec.Struct, frozen=True, tag_field="operation", tag="cancel"):
    task_id: str


class ListClosed(msgspec.Struct, frozen=True, tag_field="operation", tag="zones"):
    pass


class SetZone(msgspec.Struct, frozen=True, tag_field="operation", tag="zone"):
    """Close (`closed: true`) or open a zone."""

    zone: str
    closed: bool


class ListOutOfService(msgspec.Struct, frozen=True, tag_field="operation", tag="service"):
    pass


class SetService(msgspec.Struct, frozen=True, tag_field="operation", tag="set_service"):
    """Take a robot out of service (`in_service: false`) or put it back."""

    thing: str
    in_service: bool


class Charge(msgspec.Struct, frozen=True, tag_field="operation", tag="charge"):
    """Send a robot to the nearest free charger now."""

    thing: str


SkillRequest = (
    Submit
    | ListTasks
    | ListPending
    | Cancel
    | ListClosed
    | SetZone
    | ListOutOfService
    | SetService
    | Charge
)
OPERATIONS = (
    "submit",
    "tasks",
    "pending",
    "cancel",
    "zones",
    "zone",
    "service",
    "set_service",
    "charge",
)


class RobotUpdate(msgspec.Struct, frozen=True, kw_only=True):
    """One robot's reported state after an update, as the topic rule selects it."""

    thing: str
    reported: dict[str, Any]


class Answer(msgspec.Struct, frozen=True):
    status: int
    body: Any


# An EventBridge scheduled event's source and detail type.
SCHEDULE = ("aws.events", "Scheduled Event")


def is_tick(event: dict[str, Any]) -> bool:
    """The once-a-minute schedule (infra/constructs/dispatcher.py)."""
    return (event.get("source"), event.get("detail-type")) == SCHEDULE


def is_robot_update(event: dict[str, Any]) -> bool:
    """The rule's events carry `thing` and `reported`; the skill's carry `operation`."""
    return "operation" not in event and "thing" in event and "reported" in event
