"""The ROS 1 backend: `move_base` goals through actionlib. rospy is imported only here.

Goals are `MoveBaseGoal`s in the configured frame (`map`) at the zone's pose from
`fleet.yaml`. Feedback (`base_position`) becomes progress; an aborted, rejected or
preempted goal becomes `NavigationFailed` with move_base's status text. ROS has no arm,
so loading and unloading are timed waits, as in the simulator.

rospy allows one node per process and reads `ROS_MASTER_URI` when the node starts, so the
node is started once (by the first backend) and kept for the life of the process.
"""

from __future__ import annotations

import asyncio
import math
import os
import threading
import time
from typing import TYPE_CHECKING, Any

import actionlib
import rosgraph
import rospy
from actionlib_msgs.msg import GoalStatus
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

from robot_agent.backends.port import NavigationFailed, Progress
from vahr.domain import Pose
from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.config import Ros1Settings
    from vahr.domain import Zone

_STATUS_NAMES = {
    GoalStatus.PREEMPTED: "preempted",
    GoalStatus.ABORTED: "aborted",
    GoalStatus.REJECTED: "rejected",
    GoalStatus.RECALLED: "recalled",
    GoalStatus.LOST: "lost",
}
_node_lock = threading.Lock()


def shutdown_node(reason: str = "robot-agent stopping") -> None:
    """Shut this process's ROS node down (it cannot be started again in this process)."""
    if rospy.core.is_initialized() and not rospy.is_shutdown():
        rospy.signal_shutdown(reason)


def ensure_node(settings: Ros1Settings) -> None:
    """Start this process's ROS node once (signals stay with the agent, not rospy)."""
    with _node_lock:
        if rospy.core.is_initialized():
            return
        if settings.master_uri:
            os.environ["ROS_MASTER_URI"] = settings.master_uri
        _wait_for_master(settings.server_timeout_s)
        rospy.init_node(settings.node_name, anonymous=True, disable_signals=True)


def _wait_for_master(timeout_s: float) -> None:
    # rospy.init_node retries an unreachable master forever, so the agent would hang at
    # start-up without a word; give up after the server timeout with a one-line reason.
    master = rosgraph.Master("/vahr_robot_agent")
    deadline = time.monotonic() + timeout_s
    while not master.is_online():
        if time.monotonic() >= deadline:
            raise VahrError(
                f"--backend ros1: no ROS master at {master.master_uri} within {timeout_s:g} s "
                "(start roscore, or set ros.master_uri or ROS_MASTER_URI)"
            )
        time.sleep(0.2)


class Ros1Backend:
    """Drives a ROS 1 robot through its `move_base` action server."""

    name = "ros1"
    observed_pose = True

    def __init__(self, settings: Ros1Settings, *, start: Pose) -> None:
        self.settings = settings
        self._pose = start
        ensure_node(settings)
        self._client = actionlib.SimpleActionClient(settings.action, MoveBaseAction)
        self._server_ready = False

    @property
    def pose(self) -> Pose:
        return self._pose

    async def _wait_for_server(self) -> None:
        if self._server_ready:
            return
        timeout = rospy.Duration(self.settings.server_timeout_s)
        ready = await asyncio.to_thread(self._client.wait_for_server, timeout)
        if not ready:
            raise NavigationFailed(
                f"the {self.settings.action} action server did not answer within "
                f"{self.settings.server_timeout_s:g} s (is move_base running?)"
            )
        self._server_ready = True

    async def go_to(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        await self._wait_for_server()
        loop = asyncio.get_running_loop()
        finished: asyncio.Future[int] = loop.create_future()
        start, target = self._pose, zone.pose
        total = max(start.distance_to(target), 1e-6)

        def on_feedback(feedback: Any) -> None:
            pose = _pose_of(feedback.base_position.pose)
            self._pose = pose
            fraction = min(max(1.0 - pose.distance_to(target) / total, 0.0), 1.0)
            loop.call_soon_threadsafe(on_progress, Progress(fraction, pose))

        def on_done(state: int, result: Any) -> None:
            loop.call_soon_threadsafe(_settle, finished, state)

        self._client.send_goal(self._goal(target), done_cb=on_done, feedback_cb=on_feedback)
        try:
            state = await finished
        except asyncio.CancelledError:
            self._client.cancel_goal()
            raise
        if state != GoalStatus.SUCCEEDED:
            text = self._client.get_goal_status_text() or "no reason given"
            status = _STATUS_NAMES.get(state, f"status {state}")
            raise NavigationFailed(f"move_base goal to {zone.id} {status}: {text}")
        self._pose = target
        on_progress(Progress(1.0, target))

    def _goal(self, pose: Pose) -> MoveBaseGoal:
        goal = MoveBaseGoal()
        goal.target_pose.header.frame_id = self.settings.frame
        goal.target_pose.header.stamp = rospy.Time.now()
        goal.target_pose.pose.position.x = pose.x
        goal.target_pose.pose.position.y = pose.y
        goal.target_pose.pose.orientation.z = math.sin(pose.theta / 2)
        goal.target_pose.pose.orientation.w = math.cos(pose.theta / 2)
        return goal

    async def operate_arm(self, zone: Zone) -> None:
        delay = (
            self.settings.loader_delay_s if zone.arm == "loader" else self.settings.unloader_delay_s
        )
        await asyncio.sleep(delay)

    async def halt(self) -> None:
        if self._server_ready:
            # Every goal up to now, never a later one: a cancel-all would also cancel the
            # next command's goal should move_base take that goal before this cancel (goal
            # and cancel travel on two topics, in no order between them).
            self._client.cancel_goals_at_and_before_time(rospy.Time.now())

    def close_zones(self, closed: frozenset[str]) -> None:
        # move_base plans on the robot's own costmaps: a closed area is kept out there (a
        # keepout filter or a costmap layer), not by this backend.
        return None

    async def leave(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        # Where to go out of an area is the robot's own planner's to say; see close_zones.
        return None

    async def close(self) -> None:
        await self.halt()
        if self.settings.shutdown_node_on_close:
            shutdown_node()


def _settle(future: asyncio.Future[int], state: int) -> None:
    if not future.done():
        future.set_result(state)


def _pose_of(pose: Any) -> Pose:
    q = pose.orientation
    theta = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
    return Pose(pose.position.x, pose.position.y, theta)
