"""The `NavigationBackend` port: how the executor drives a robot, whatever the robot is.

A backend drives to a zone's pose, reports progress while it does, operates the zone's arm,
and halts at once when asked. A goal that cannot be reached raises `NavigationFailed` with
a reason a person can act on; cancelling the awaiting task cancels the goal.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain import Pose, Zone


@dataclass(frozen=True)
class Progress:
    """How far along a goal is: `fraction` of the path done (0..1) and where the robot is.

    `at` is when the backend observed it, in the executor's clock's (simulated) seconds,
    from a backend that keeps the time of its own motion (the simulator): the executor then
    judges "no progress" by that time, which a busy process cannot advance without the
    motion advancing too. None: the backend does not, and the executor's clock is used.
    """

    fraction: float
    pose: Pose
    at: float | None = None


class NavigationFailed(Exception):
    """The backend could not reach the goal (aborted, rejected, blocked); says why."""


class NavigationBackend(Protocol):
    name: str

    @property
    def pose(self) -> Pose:
        """Where the robot is now, in the `map` frame."""

    async def go_to(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        """Drive to `zone`; return on arrival, raise NavigationFailed, or halt when cancelled."""

    async def operate_arm(self, zone: Zone) -> None:
        """Wait while the zone's arm loads (LOADING) or unloads (a delivery zone) the robot."""

    async def halt(self) -> None:
        """Stop moving at once and drop any active goal."""

    async def close(self) -> None:
        """Release the backend's resources (threads, nodes, connections)."""
