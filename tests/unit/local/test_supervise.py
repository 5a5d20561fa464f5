"""`vahr up` restarts a robot-agent that died, says so in one line, and gives up on one
that keeps dying (the processes themselves: tests/integration/soak)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from vahr.errors import VahrError
from vahr.local.system import RESTART_LIMIT, LocalSystem, SystemConfig

if TYPE_CHECKING:
    from pathlib import Path


class DyingRobots:
    """Stands in for RobotProcesses: `placebot1` has exited every time it is asked."""

    def __init__(self) -> None:
        self.restarted: list[str] = []

    def exited(self) -> dict[str, int]:
        return {"placebot1": -9}

    def restart(self, thing: str) -> None:
        self.restarted.append(thing)

    def stop(self) -> None:
        pass


def test_a_dead_robot_is_restarted_with_one_line_until_it_keeps_dying(tmp_path: Path) -> None:
    # Given vahr up whose robot placebot1 was killed
    system = LocalSystem(SystemConfig(state_dir=tmp_path, mqtts_port=1, mqtt_port=None, api_port=2))
    robots = DyingRobots()
    system.robots = robots  # type: ignore[assignment]
    # When it is noticed, then it is started again and one line says so
    assert system.supervise() == [
        "robot placebot1 stopped unexpectedly (exit code -9); restarted it"
    ]
    for _ in range(RESTART_LIMIT - 1):
        system.supervise()
    assert robots.restarted == ["placebot1"] * RESTART_LIMIT
    # And when it dies once more within the minute, vahr up stops saying why
    with pytest.raises(
        VahrError, match=r"robot placebot1 stopped unexpectedly .* 6 times within 60 s"
    ):
        system.supervise()
    assert len(robots.restarted) == RESTART_LIMIT
