"""Every navigation backend behaves the same to the executor: one suite, run on each.

Each test runs on the simulator, on ROS 1 (move_base through a real ROS master, a fake
move_base: tests/support/ros1.py) and on ROS 2 (Nav2's NavigateToPose through real rclpy and
Fast DDS, a stand-in bt_navigator: tests/support/nav2_stand_in.py). ROS 1 lives in .venv and
ROS 2 in .venv-ros2, so each venv runs the backends it has and skips the other with the
reason; `make test` runs the ros1 cases in .venv and the nav2 ones (marked ros2) in
.venv-ros2.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import pytest

from robot_agent.clock import ScaledClock
from robot_agent.config import ExecutorSettings, SimSettings
from robot_agent.core.executor import Executor
from tests.support.nav2 import HAS_ROS2, WITHOUT_ROS2
from tests.unit.agent.conftest import Recorder, make_executor
from tests.unit.agent.test_agent_weather_delivery import SUNNY, ScriptedAssistant
from vahr.protocol import Event, new_command, utc_now

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.backends.port import NavigationBackend
    from vahr.domain import Fleet

HAS_ROS1 = importlib.util.find_spec("rospy") is not None
WITHOUT_ROS1 = "needs ROS 1's rospy (Debian's packages, seen by .venv through make setup)"


@dataclass
class Robot:
    """A robot on one backend, and what its navigation server saw."""

    executor: Executor
    rec: Recorder
    backend: NavigationBackend
    # Makes the next goal abort on the server, and part of the reason the robot then gives.
    abort_next: Callable[[], str]
    # The (x, y) of every goal the server received after this robot was made, and how many
    # cancels it honoured; None for the simulator, which has no server.
    targets: Callable[[], list[tuple[float, float]]] | None = None
    cancels: Callable[[], int] | None = None

    def server_saw(self, *targets: tuple[float, float]) -> None:
        """The navigation server received goals at exactly these targets, in order."""
        if self.targets is not None:
            assert self.targets() == list(targets)

    async def server_cancelled(self, count: int) -> None:
        """The server honoured `count` cancels (it may say so a moment after the robot)."""
        cancels = self.cancels
        if cancels is not None:
            await _eventually(lambda: cancels() == count)


def _settings() -> ExecutorSettings:
    # Every backend step reported, and a stuck time no test comes near.
    return ExecutorSettings(stuck_after_s=30, progress_interval_s=0, progress_step=0)


def _sim(fleet: Fleet, request: pytest.FixtureRequest, voice: Any) -> Robot:
    executor, rec, backend = make_executor(
        fleet,
        voice=voice,
        sim=SimSettings(loader_delay_s=1, unloader_delay_s=1),
        settings=_settings(),
        speed=100,
    )

    def abort_next() -> str:
        backend.inject_failure("the planner found no path")
        return "goal to D aborted: the planner found no path"

    return Robot(executor, rec, backend, abort_next)


def _ros1(fleet: Fleet, request: pytest.FixtureRequest, voice: Any) -> Robot:
    from robot_agent.backends.ros1 import Ros1Backend
    from robot_agent.config import Ros1Settings

    master = request.getfixturevalue("ros_master")
    move_base = request.getfixturevalue("move_base")
    backend = Ros1Backend(
        Ros1Settings(
            master_uri=master,
            loader_delay_s=0.05,
            unloader_delay_s=0.05,
            # The node serves the whole session (the fake move_base is on it too).
            shutdown_node_on_close=False,
        ),
        start=fleet.robot("placebot1").start,
    )
    # This fake move_base aborts every goal into zone D.
    goals, preempted = len(move_base["goals"]), move_base["preempted"]

    def targets() -> list[tuple[float, float]]:
        return [
            (g.target_pose.pose.position.x, g.target_pose.pose.position.y)
            for g in move_base["goals"][goals:]
        ]

    return Robot(
        _executor(fleet, backend, voice),
        _recorder_of(backend),
        backend,
        abort_next=lambda: "move_base goal to D aborted: no path through the costmap",
        targets=targets,
        cancels=lambda: move_base["preempted"] - preempted,
    )


def _nav2(fleet: Fleet, request: pytest.FixtureRequest, voice: Any) -> Robot:
    from robot_agent.backends.nav2 import Nav2Backend
    from robot_agent.config import Nav2Settings

    stand_in = request.getfixturevalue("nav2_stand_in")
    stand_in.plan()
    backend = Nav2Backend(
        Nav2Settings(domain_id=stand_in.domain_id, loader_delay_s=0.05, unloader_delay_s=0.05),
        start=fleet.robot("placebot1").start,
    )
    seen = len(stand_in.log())

    def since(event: str) -> list[dict[str, Any]]:
        return [e for e in stand_in.log()[seen:] if e["event"] == event]

    def abort_next() -> str:
        # Every goal from now on (the plan is reset for the next robot): on a busy machine
        # the goal's request is sent again after RESEND_S, or one of the test before arrives
        # late, and an abort queued for one goal went to that request instead of the goal
        # the robot followed, which then succeeded.
        stand_in.plan(
            default={"mode": "abort", "error_code": 204, "error_msg": "no valid path found"}
        )
        return "Nav2 aborted the goal to D (error_code 204): no valid path found"

    return Robot(
        _executor(fleet, backend, voice),
        _recorder_of(backend),
        backend,
        abort_next=abort_next,
        targets=lambda: [(e["x"], e["y"]) for e in since("goal")],
        cancels=lambda: len(since("canceled")),
    )


# The executor of a ROS backend publishes into a recorder kept beside the backend.
_recorders: dict[int, Recorder] = {}


def _executor(fleet: Fleet, backend: NavigationBackend, voice: Any) -> Executor:
    recorder = _recorders[id(backend)] = Recorder()
    return Executor(
        thing="placebot1",
        fleet=fleet,
        backend=backend,
        clock=ScaledClock(1.0),
        publish_state=recorder.states.append,
        publish_event=recorder.events.append,
        voice=voice,
        settings=_settings(),
    )


def _recorder_of(backend: NavigationBackend) -> Recorder:
    return _recorders.pop(id(backend))


BACKENDS = [
    pytest.param(_sim, id="sim"),
    pytest.param(
        _ros1,
        id="ros1",
        marks=[pytest.mark.ros, pytest.mark.skipif(not HAS_ROS1, reason=WITHOUT_ROS1)],
    ),
    pytest.param(
        _nav2,
        id="nav2",
        marks=[pytest.mark.ros2, pytest.mark.skipif(not HAS_ROS2, reason=WITHOUT_ROS2)],
    ),
]


@pytest.fixture(params=BACKENDS)
def make_robot(request: pytest.FixtureRequest, fleet: Fleet) -> Callable[..., Robot]:
    """Builds the robot inside the test (ROS backends hand their feedback to the running
    event loop); `voice` is its Voice, if any."""

    def make(voice: Any = None) -> Robot:
        return request.param(fleet, request, voice)

    return make


def cmd(action: str, params: dict[str, Any] | None, command_id: str) -> Any:
    return new_command(action, params, source="console", command_id=command_id)


async def test_navigate_drives_to_the_zone_s_pose_and_reports_the_way(
    make_robot: Callable[..., Robot], fleet: Fleet
) -> None:
    robot = make_robot()
    # When the robot is sent to zone B
    robot.executor.execute(cmd("navigate", {"zone": "B"}, "n1"))
    await robot.executor.wait_idle()
    await robot.executor.close()
    # Then its server got a goal at B's pose (the simulator drove there itself)
    robot.server_saw((9.0, 5.0))
    # and it reported its way there, then arrived and was done
    rec = robot.rec
    progress = [e.progress for e in rec.events if e.event == "progress"]
    assert progress and progress == sorted(progress) and 0 < progress[0] and progress[-1] < 1
    assert rec.kinds("n1")[0] == "accepted" and rec.kinds("n1")[-2:] == ["arrived", "done"]
    final = rec.states[-1]
    assert (final.status, final.zone, final.last_command.result) == ("idle", "B", "done")  # type: ignore[union-attr]
    assert final.pose is not None and (final.pose.x, final.pose.y) == (9.0, 5.0)


async def test_deliver_loads_at_loading_and_unloads_in_the_zone(
    make_robot: Callable[..., Robot],
) -> None:
    robot = make_robot()
    robot.executor.execute(cmd("deliver", {"zone": "C"}, "d1"))
    await robot.executor.wait_idle()
    await robot.executor.close()
    robot.server_saw((1.5, 4.0), (9.0, 3.0))
    kinds = [k for k in robot.rec.kinds("d1") if k != "progress"]
    assert kinds == ["accepted", "arrived", "loaded", "arrived", "delivered", "done"]
    assert robot.rec.first("loaded").zone == "LOADING"
    assert robot.rec.first("delivered").zone == "C"
    final = robot.rec.states[-1]
    assert (final.status, final.zone, final.cargo) == ("idle", "C", False)
    assert any(state.cargo for state in robot.rec.states)


async def test_stop_cancels_the_goal_at_once_and_the_robot_reports_stopped(
    make_robot: Callable[..., Robot],
) -> None:
    robot = make_robot()
    robot.executor.execute(cmd("navigate", {"zone": "A"}, "s1"))
    await robot.rec.until("progress", "s1")
    # When a stop arrives while it drives
    robot.executor.execute(cmd("stop", None, "s2"))
    await robot.executor.wait_idle()
    # Then the drive ends cancelled, the goal is cancelled on the server, the robot is stopped
    assert robot.rec.kinds("s1")[-1] == "cancelled"
    assert robot.rec.kinds("s2") == ["accepted", "stopped", "done"]
    final = robot.rec.states[-1]
    assert final.status == "stopped" and final.zone is None
    robot.server_saw((9.0, 7.0))
    await robot.server_cancelled(1)
    await robot.executor.close()


async def test_a_new_motion_command_preempts_the_goal(make_robot: Callable[..., Robot]) -> None:
    robot = make_robot()
    robot.executor.execute(cmd("navigate", {"zone": "A"}, "p1"))
    await robot.rec.until("progress", "p1")
    robot.executor.execute(cmd("navigate", {"zone": "C"}, "p2"))
    await robot.executor.wait_idle()
    await robot.executor.close()
    # The first goal is cancelled, then the second is sent and reached
    assert robot.rec.first("cancelled", "p1").reason == "preempted by navigate p2"
    assert robot.rec.kinds("p2")[-2:] == ["arrived", "done"]
    robot.server_saw((9.0, 7.0), (9.0, 3.0))
    await robot.server_cancelled(1)
    assert robot.rec.states[-1].zone == "C"


async def test_an_aborted_goal_fails_with_the_server_s_reason(
    make_robot: Callable[..., Robot],
) -> None:
    robot = make_robot()
    reason = robot.abort_next()
    robot.executor.execute(cmd("navigate", {"zone": "D"}, "f1"))
    await robot.executor.wait_idle()
    await robot.executor.close()
    assert robot.rec.first("failed", "f1").reason == reason
    final = robot.rec.states[-1]
    assert final.status == "error"
    assert final.last_command is not None and (
        final.last_command.result,
        final.last_command.reason,
    ) == ("failed", reason)


async def test_sequential_delivery_waits_for_the_peer_then_delivers(
    make_robot: Callable[..., Robot],
) -> None:
    robot = make_robot()
    robot.executor.execute(cmd("sequential_delivery", {"zone": "B", "after": "placebot2"}, "q1"))
    await robot.rec.until("waiting", "q1")
    # When the peer delivers
    robot.executor.peer_event(Event(event="delivered", thing="placebot2", at=utc_now(), zone="A"))
    await robot.executor.wait_idle()
    await robot.executor.close()
    assert robot.rec.kinds("q1")[-2:] == ["delivered", "done"]
    assert robot.rec.first("delivered", "q1").zone == "B"


async def test_weather_delivery_asks_by_voice_then_delivers(
    make_robot: Callable[..., Robot],
) -> None:
    robot = make_robot(voice=ScriptedAssistant(SUNNY))
    robot.executor.execute(cmd("weather_delivery", None, "w1"))
    await robot.executor.wait_idle()
    await robot.executor.close()
    assert [e.event for e in robot.rec.events if e.event in ("said", "heard")][:2] == [
        "said",
        "heard",
    ]
    assert robot.rec.first("delivered", "w1").zone == "A"
    robot.server_saw((1.5, 4.0), (9.0, 7.0))


async def _eventually(condition: Callable[[], bool], timeout_s: float = 5.0) -> None:
    import asyncio

    async with asyncio.timeout(timeout_s):
        while not condition():
            await asyncio.sleep(0.01)
