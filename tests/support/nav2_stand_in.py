"""A stand-in for Nav2's bt_navigator, NOT Nav2: a real rclpy NavigateToPose action server.

It plans nothing and sees no map. It glides a point from where it stands to each goal,
publishing NavigateToPose feedback on the way (`current_pose`, `distance_remaining`,
`estimated_time_remaining`, `navigation_time`), and ends the goal as the test asks: succeed,
abort with an error code and message, reject, stall (accept and never say a word), die part
way (the process exits), or see its goal cancelled by another client. It honours cancel
requests (or refuses them, when asked to), and publishes a `sensor_msgs/BatteryState`.

Run it as its own process, in a ROS 2 venv (tests start it through `tests.support.nav2`):

    python -m tests.support.nav2_stand_in --control DIR [--action navigate_to_pose]
        [--domain-id N] [--start X,Y]

The test steers it through files in DIR: `plan.json` (`{"default": {...}, "queue": [...]}`,
one mode per goal, the queue first), `battery.json` (`{"percentage": 0..1, "status": N}`).
It writes `ready` once serving, and one JSON line per thing that happened to `log.jsonl`
(`goal` with the target, `accepted`, `rejected`, `feedback`, `cancel_requested`, and the
end: `succeeded`, `aborted`, `canceled`), each with `at`, `time.monotonic()`.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import threading
import time
from pathlib import Path
from typing import Any

import rclpy
from action_msgs.srv import CancelGoal
from nav2_msgs.action import NavigateToPose
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from sensor_msgs.msg import BatteryState

DEFAULT_MODE: dict[str, Any] = {"mode": "succeed", "steps": 10, "step_s": 0.04}


class StandIn:
    """The action server, its battery publisher and the control files."""

    def __init__(self, node: Any, control: Path, action: str, start: tuple[float, float]) -> None:
        self.node = node
        self.control = control
        self.position = start
        self._log_lock = threading.Lock()
        group = ReentrantCallbackGroup()
        self.server = ActionServer(
            node,
            NavigateToPose,
            action,
            execute_callback=self.execute,
            goal_callback=self.on_goal,
            cancel_callback=self.on_cancel,
            callback_group=group,
        )
        # Another client's cancel, as a second operator or Nav2's own tools would send it.
        self.canceller = node.create_client(
            CancelGoal, f"{action}/_action/cancel_goal", callback_group=group
        )
        self.battery = node.create_publisher(BatteryState, "battery_state", 10)
        node.create_timer(0.1, self.publish_battery, callback_group=group)

    def log(self, event: str, **fields: Any) -> None:
        line = json.dumps({"event": event, "at": time.monotonic(), **fields})
        with self._log_lock, (self.control / "log.jsonl").open("a") as log:
            log.write(line + "\n")

    def next_mode(self) -> dict[str, Any]:
        path = self.control / "plan.json"
        plan = json.loads(path.read_text()) if path.exists() else {}
        queue = plan.get("queue") or []
        if queue:
            mode = queue.pop(0)
            plan["queue"] = queue
            path.write_text(json.dumps(plan))
        else:
            mode = plan.get("default") or {}
        return {**DEFAULT_MODE, **mode}

    def on_goal(self, request: Any) -> GoalResponse:
        mode = self.next_mode()
        pose = request.pose
        q = pose.pose.orientation
        self.log(
            "goal",
            x=pose.pose.position.x,
            y=pose.pose.position.y,
            theta=math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z),
            frame=pose.header.frame_id,
            behavior_tree=request.behavior_tree,
            mode=mode["mode"],
        )
        if mode["mode"] == "reject":
            self.log("rejected")
            return GoalResponse.REJECT
        self._pending = mode
        # A slow answer: a stop can overtake it on the robot.
        time.sleep(mode.get("accept_delay_s", 0))
        self.log("accepted")
        return GoalResponse.ACCEPT

    def on_cancel(self, goal_handle: Any) -> CancelResponse:
        self.log("cancel_requested")
        if self._pending.get("refuse_cancel"):
            self.log("cancel_refused")
            return CancelResponse.REJECT
        return CancelResponse.ACCEPT

    def execute(self, goal_handle: Any) -> Any:
        mode = self._pending
        kind = mode["mode"]
        target = goal_handle.request.pose.pose.position
        start = self.position
        steps, step_s = int(mode["steps"]), float(mode["step_s"])
        total = math.dist(start, (target.x, target.y))
        began = time.monotonic()
        result = NavigateToPose.Result()
        stop_at = {"abort": steps // 2, "die": steps // 2, "cancel_elsewhere": steps // 2}
        for step in range(1, steps + 1):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                self.log("canceled")
                return result
            if kind == "stall":
                time.sleep(step_s)
                continue
            if step == stop_at.get(kind):
                if kind == "abort":
                    result.error_code = int(mode.get("error_code", 0))
                    result.error_msg = str(mode.get("error_msg", ""))
                    goal_handle.abort()
                    self.log("aborted")
                    return result
                if kind == "die":
                    self.log("died")
                    os._exit(3)
                if kind == "cancel_elsewhere":
                    self.canceller.call_async(CancelGoal.Request())  # every goal
            fraction = step / steps
            self.position = (
                start[0] + (target.x - start[0]) * fraction,
                start[1] + (target.y - start[1]) * fraction,
            )
            feedback = NavigateToPose.Feedback()
            feedback.current_pose.header.frame_id = "map"
            feedback.current_pose.pose.position.x = self.position[0]
            feedback.current_pose.pose.position.y = self.position[1]
            feedback.current_pose.pose.orientation = goal_handle.request.pose.pose.orientation
            if not mode.get("pose_only"):  # else only current_pose, as a plain server may
                feedback.distance_remaining = float(total * (1 - fraction))
                remaining_s = (steps - step) * step_s
                feedback.estimated_time_remaining.sec = int(remaining_s)
                feedback.estimated_time_remaining.nanosec = int((remaining_s % 1) * 1e9)
            elapsed = time.monotonic() - began
            feedback.navigation_time.sec = int(elapsed)
            feedback.navigation_time.nanosec = int((elapsed % 1) * 1e9)
            goal_handle.publish_feedback(feedback)
            self.log("feedback", x=self.position[0], y=self.position[1])
            time.sleep(step_s)
        if kind == "stall":
            # Still stalled after its steps: it never answers unless cancelled.
            while not goal_handle.is_cancel_requested and rclpy.ok():
                time.sleep(0.01)
            goal_handle.canceled()
            self.log("canceled")
            return result
        goal_handle.succeed()
        self.log("succeeded")
        return result

    def publish_battery(self) -> None:
        path = self.control / "battery.json"
        if not path.exists():
            return
        setting = json.loads(path.read_text())
        message = BatteryState()
        message.percentage = float(setting["percentage"])
        message.power_supply_status = int(setting.get("status", 0))
        message.present = True
        self.battery.publish(message)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--control", type=Path, required=True)
    parser.add_argument("--action", default="navigate_to_pose")
    parser.add_argument("--domain-id", type=int)
    parser.add_argument("--start", default="1.0,3.0")
    args = parser.parse_args()
    x, y = (float(value) for value in args.start.split(","))
    rclpy.init(domain_id=args.domain_id)
    node = rclpy.create_node("nav2_stand_in")
    StandIn(node, args.control, args.action, (x, y))
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    (args.control / "ready").write_text(str(os.getpid()))
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # SIGINT or SIGTERM: rclpy's handlers shut the context down
    finally:
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
