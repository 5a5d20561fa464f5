"""The ros1 backend drives move_base goals through a real ROS master and action server.

The test uses a real `rosmaster --core` on a free loopback port and a fake `move_base`
(`tests/support/ros1.py`) that glides towards the goal with feedback, aborts goals into
zone D (as a blocked planner would), and honours preemption.
"""

from __future__ import annotations

import math
import signal
import subprocess
from typing import TYPE_CHECKING, Any

import pytest

from robot_agent.clock import ScaledClock
from robot_agent.config import ExecutorSettings
from robot_agent.core.executor import Executor
from tests.support.ros1 import STEPS
from tests.unit.agent.conftest import Recorder
from vahr.plumbing.ports import free_port
from vahr.protocol import new_command

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain import Fleet

pytestmark = pytest.mark.ros


def ros_executor(fleet: Fleet, ros_master: str) -> tuple[Executor, Recorder]:
    from robot_agent.backends.ros1 import Ros1Backend
    from robot_agent.config import Ros1Settings

    backend = Ros1Backend(
        Ros1Settings(
            master_uri=ros_master, loader_delay_s=0.05, unloader_delay_s=0.05, server_timeout_s=10
        ),
        start=fleet.robot("placebot1").start,
    )
    recorder = Recorder()
    executor = Executor(
        thing="placebot1",
        fleet=fleet,
        backend=backend,
        clock=ScaledClock(1.0),
        publish_state=recorder.states.append,
        publish_event=recorder.events.append,
        settings=ExecutorSettings(progress_interval_s=0.0, progress_step=0.0, stuck_after_s=5),
    )
    return executor, recorder


async def test_a_navigate_command_becomes_a_move_base_goal_in_the_map_frame(
    fleet: Fleet, ros_master: str, move_base: dict[str, Any]
) -> None:
    executor, rec = ros_executor(fleet, ros_master)
    before = len(move_base["goals"])
    executor.execute(new_command("navigate", {"zone": "B"}, source="console", command_id="r1"))
    await executor.wait_idle()
    goal = move_base["goals"][before]
    assert goal.target_pose.header.frame_id == "map"
    assert (goal.target_pose.pose.position.x, goal.target_pose.pose.position.y) == (9.0, 5.0)
    assert math.isclose(goal.target_pose.pose.orientation.w, 1.0)
    progress = [e.progress for e in rec.events if e.event == "progress"]
    assert len(progress) >= STEPS // 2 and progress == sorted(progress)
    assert rec.kinds("r1")[-2:] == ["arrived", "done"]
    assert rec.states[-1].zone == "B"


async def test_an_aborted_goal_fails_with_move_base_s_reason(
    fleet: Fleet, ros_master: str, move_base: dict[str, Any]
) -> None:
    executor, rec = ros_executor(fleet, ros_master)
    executor.execute(new_command("navigate", {"zone": "D"}, source="console", command_id="r2"))
    await executor.wait_idle()
    assert (
        rec.first("failed", "r2").reason
        == "move_base goal to D aborted: no path through the costmap"
    )
    assert rec.states[-1].status == "error"


async def test_stop_preempts_the_active_goal(
    fleet: Fleet, ros_master: str, move_base: dict[str, Any]
) -> None:
    import asyncio

    executor, rec = ros_executor(fleet, ros_master)
    preempted = move_base["preempted"]
    executor.execute(new_command("navigate", {"zone": "A"}, source="console", command_id="r3"))
    await rec.until("progress", "r3")
    executor.execute(new_command("stop", None, source="console", command_id="r4"))
    await executor.wait_idle()
    async with asyncio.timeout(5):
        while move_base["preempted"] == preempted:
            await asyncio.sleep(0.01)
    assert rec.kinds("r3")[-1] == "cancelled"
    assert rec.states[-1].status == "stopped"


def test_robot_agent_run_with_the_ros1_backend_drives_move_base_from_mqtt(
    ros_master: str, move_base: dict[str, Any], mosquitto: Any, tmp_path: Path
) -> None:
    from tests.integration.agent.harness import AgentProcess, ShadowResponder, WireTap, command

    port = mosquitto.config.plain_port
    tap, shadows = WireTap(port), ShadowResponder(port)
    config = tmp_path / "ros.yaml"
    config.write_text(
        f"ros:\n  master_uri: {ros_master}\n  loader_delay_s: 0.05\n  unloader_delay_s: 0.05\n"
    )
    agent = AgentProcess(
        "--thing",
        "placebot1",
        "--broker",
        str(mosquitto.plain_url),
        "--backend",
        "ros1",
        "--config",
        str(config),
        state_dir=tmp_path / "state",
        log_file=tmp_path / "agent.log",
    )
    try:
        tap.reported("placebot1", lambda r: r["connected"] is True, timeout_s=20)
        goals = len(move_base["goals"])
        # When a deliver command arrives over MQTT
        tap.publish("vahr/robots/placebot1/cmd", command("ros-deliver", "deliver", {"zone": "C"}))
        # Then move_base gets a goal for LOADING, then one for zone C, and the robot delivers
        tap.event("placebot1", "delivered", "ros-deliver", timeout_s=20)
        targets = [
            (g.target_pose.pose.position.x, g.target_pose.pose.position.y)
            for g in move_base["goals"][goals:]
        ]
        assert targets == [(1.5, 4.0), (9.0, 3.0)]
        state = tap.reported(
            "placebot1", lambda r: (r["last_command"] or {}).get("result") == "done"
        )
        assert state["zone"] == "C"
        # and it stops cleanly (its ROS node too), exit code 0
        assert agent.stop(signal.SIGTERM, timeout_s=15) == 0, agent.log()
    finally:
        if agent.process.poll() is None:
            agent.kill()
        tap.close()
        shadows.close()


def test_robot_agent_run_without_a_ros_master_exits_with_a_one_line_error(
    tmp_path: Path,
) -> None:
    from tests.integration.agent.harness import AgentProcess

    # Given no ROS master on the configured port
    config = tmp_path / "ros.yaml"
    config.write_text(
        f"ros:\n  master_uri: http://127.0.0.1:{free_port()}\n  server_timeout_s: 1\n"
    )
    # When the agent starts with the ros1 backend
    agent = AgentProcess(
        "--thing",
        "placebot1",
        "--broker",
        f"mqtt://127.0.0.1:{free_port()}",
        "--backend",
        "ros1",
        "--config",
        str(config),
        state_dir=tmp_path / "state",
        log_file=tmp_path / "agent.log",
    )
    try:
        code = agent.process.wait(timeout=20)
    except subprocess.TimeoutExpired:
        agent.kill()
        pytest.fail("robot-agent run waited for the ROS master without a timeout")
    agent.stop()
    # Then it exits non-zero with one line naming the master it could not reach
    assert code != 0
    # (rospy logs its own start-up lines too; the agent's reason is one line of its own)
    errors = [line for line in agent.log().splitlines() if "error:" in line]
    assert len(errors) == 1, agent.log()
    assert "no ROS master at http://127.0.0.1:" in errors[0]
