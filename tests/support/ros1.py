"""ROS 1 for tests: a real ROS master and a fake `move_base` (not the real one).

`ros_master` starts `rosmaster --core` on a free loopback port; `move_base` is an actionlib
`SimpleActionServer` with `MoveBaseAction` in the test process that glides towards each
goal with feedback, aborts goals into zone D (as a blocked planner would), and honours
preemption. Both live for the test session; the agent's conftest registers them.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from typing import TYPE_CHECKING, Any

import pytest

from vahr.plumbing.lifetime import spawn
from vahr.plumbing.ports import free_port, wait_for_listener

if TYPE_CHECKING:
    from collections.abc import Iterator

STEPS = 8
STEP_S = 0.05


@pytest.fixture(scope="session")
def ros_master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    port = free_port()
    home = tmp_path_factory.mktemp("ros-home")
    env = dict(
        os.environ,
        ROS_IP="127.0.0.1",
        ROS_HOME=str(home),
        ROS_MASTER_URI=f"http://127.0.0.1:{port}",
    )
    # The master dies with the test run even if pytest is killed (no preexec_fn: pytest
    # has threads by now, and running Python between fork and exec could deadlock).
    process = spawn(
        ["rosmaster", "--core", "-p", str(port), "-w", "3"],
        started_for=home,
        death_signal=signal.SIGTERM,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        wait_for_listener(port, 10, "ROS master")
        # rospy reads these when the node starts (once per process).
        for name in ("ROS_IP", "ROS_HOME", "ROS_MASTER_URI"):
            os.environ[name] = env[name]
        yield env["ROS_MASTER_URI"]
    finally:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=5)


@pytest.fixture(scope="session")
def move_base(ros_master: str) -> Iterator[dict[str, Any]]:
    """A fake move_base in this process; records the goals it received."""
    from robot_agent.backends.ros1 import ensure_node
    from robot_agent.config import Ros1Settings

    ensure_node(Ros1Settings(master_uri=ros_master, node_name="vahr_agent_test"))
    import actionlib
    from move_base_msgs.msg import MoveBaseAction, MoveBaseFeedback

    seen: dict[str, Any] = {"goals": [], "preempted": 0}
    position = {"x": 1.0, "y": 3.0}

    def execute(goal: Any) -> None:
        seen["goals"].append(goal)
        target = goal.target_pose.pose.position
        x0, y0 = position["x"], position["y"]
        for step in range(1, STEPS + 1):
            if server.is_preempt_requested():
                seen["preempted"] += 1
                server.set_preempted(text="cancelled by the client")
                return
            if target.y < 2 and step == STEPS // 2:
                server.set_aborted(text="no path through the costmap")
                return
            feedback = MoveBaseFeedback()
            feedback.base_position.header.frame_id = "map"
            position["x"] = x0 + (target.x - x0) * step / STEPS
            position["y"] = y0 + (target.y - y0) * step / STEPS
            feedback.base_position.pose.position.x = position["x"]
            feedback.base_position.pose.position.y = position["y"]
            feedback.base_position.pose.orientation.w = 1.0
            server.publish_feedback(feedback)
            time.sleep(STEP_S)
        server.set_succeeded(text="goal reached")

    server = actionlib.SimpleActionServer(
        "move_base", MoveBaseAction, execute_cb=execute, auto_start=False
    )
    server.start()
    yield seen
    from robot_agent.backends.ros1 import shutdown_node

    # rospy's threads would keep the test process alive after the session otherwise.
    shutdown_node("tests done")
