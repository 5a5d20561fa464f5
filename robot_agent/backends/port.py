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
    A backend that plans on a map also gives `path` (the planned points to the goal, new
    whenever it plans again) and `eta_s` (seconds left along it).
    """

    fraction: float
    pose: Pose
    at: float | None = None
    path: tuple[tuple[float, float], ...] | None = None
    eta_s: float | None = None


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

    def close_zones(self, closed: frozenset[str]) -> None:
        """The zones closed now: a backend that plans drives around their areas from now
        on (a drive under way plans again); one that does not may ignore it."""

    async def leave(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        """Drive out of `zone`'s area (it closed with the robot inside) to the nearest
        place outside it; return at once where the backend does not plan."""

    async def close(self) -> None:
        """Release the backend's resources (threads, nodes, connections)."""
