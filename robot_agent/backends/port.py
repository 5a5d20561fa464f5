"""The `NavigationBackend` port: how the executor drives a robot, whatever the robot is.

A backend drives to a zone's pose, reports progress while it does, operates the zone's arm,
and halts at once when asked. A goal that cannot be reached raises `NavigationFailed` with
a reason a person can act on (`GoalRejected` when the robot's navigation server refused the
goal, `GoalCancelled` when it cancelled the goal on its own); cancelling the awaiting task
cancels the goal. A backend that reads the robot's battery is also a `BatteryGauge`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain import Pose, Zone
    from vahr.protocol import Battery, Result, Status


@dataclass(frozen=True)
class Progress:
    """How far along a goal is: `fraction` of the path done (0..1) and where the robot is.

    `at` is when the backend observed it, in the executor's clock's (simulated) seconds,
    from a backend that keeps the time of its own motion (the simulator): the executor then
    judges "no progress" by that time, which a busy process cannot advance without the
    motion advancing too. None: the backend does not, and the executor's clock is used.
    `eta_s` and `distance_remaining_m` are the navigation server's own estimates (Nav2's
    `estimated_time_remaining` and `distance_remaining`), where it gives them; a simulated
    robot on a map gives `eta_s` as the seconds left along its path. A backend that plans
    on a map also gives `path` (the planned points to the goal, new whenever it plans
    again).
    """

    fraction: float
    pose: Pose
    at: float | None = None
    path: tuple[tuple[float, float], ...] | None = None
    eta_s: float | None = None
    distance_remaining_m: float | None = None


class NavigationFailed(Exception):
    """The backend could not reach the goal (aborted, blocked, no server); says why.

    `result` is how the command ends and `status` what the robot reports afterwards.
    """

    result: ClassVar[Result] = "failed"
    status: ClassVar[Status] = "error"


class GoalRejected(NavigationFailed):
    """The navigation server refused the goal: the robot did not move for it."""

    result = "rejected"
    status = "idle"


class GoalCancelled(NavigationFailed):
    """The navigation server cancelled the goal itself (this robot did not ask it to)."""

    result = "cancelled"
    status = "idle"


class NavigationBackend(Protocol):
    name: str
    # True when `pose` is the robot's own localisation (ROS): the shadow's `pose` then follows
    # the progress reports. False for the simulator, whose pose its events carry.
    observed_pose: bool

    @property
    def pose(self) -> Pose:
        """Where the robot is now, in the `map` frame."""

    async def go_to(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        """Drive to `zone`; return on arrival, raise NavigationFailed, or halt when cancelled."""

    async def operate_arm(self, zone: Zone) -> None:
        """Wait while the zone's arm loads (LOADING) or unloads (a delivery zone) the robot."""

    async def halt(self) -> None:
        """Stop moving at once and drop any active goal."""

    def close_zones(self, closed: frozenset[str]) -> None:
        """The zones closed now: a backend that plans drives around their areas from now
        on (a drive under way plans again); one that does not may ignore it."""

    async def leave(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        """Drive out of `zone`'s area (it closed with the robot inside) to the nearest
        place outside it; return at once where the backend does not plan."""

    async def close(self) -> None:
        """Release the backend's resources (threads, nodes, connections)."""


@runtime_checkable
class BatteryGauge(Protocol):
    """A backend that reads the robot's battery."""

    def watch_battery(self, on_battery: Callable[[Battery], None]) -> None:
        """Call `on_battery` on the event loop with every reading from now on."""
