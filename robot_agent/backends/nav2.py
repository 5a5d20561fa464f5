"""The ROS 2 backend: Nav2's NavigateToPose action through rclpy. rclpy is imported only here.

Goals are `nav2_msgs/action/NavigateToPose` goals to the configured action (bt_navigator's
`navigate_to_pose`) at the zone's pose from `fleet.yaml`, in the configured frame (`map`).
Feedback becomes progress: `current_pose` is where the robot is, `distance_remaining` and
`estimated_time_remaining` go into the progress report (where Nav2 knows them). The goal's
end maps onto the command's: succeeded is done, aborted fails with Nav2's `error_code` and
`error_msg`, canceled by the server ends cancelled, a rejected goal is rejected.

Nothing waits without a bound: a server that is not there, does not answer a goal or a
cancel, or goes silent (dies) while it navigates fails the goal with a reason after
`server_timeout_s`, `answer_timeout_s` or `feedback_timeout_s`; the agent keeps running and
the next goal finds the server again when it is back (DDS discovery does that by itself).

The backend owns an rclpy context of its own (with the configured domain, and no signal
handlers: signals stay with the agent), one node and one thread that spins it. Every rclpy
call runs on that thread too (rclpy registers the future of a request after sending it, so
a reply taken by another thread in between would be lost), and everything comes back to the
event loop through futures. The robot's `sensor_msgs/BatteryState` is read on
`battery_topic`.
"""

from __future__ import annotations

import asyncio
import logging
import math
import threading
import time
from typing import TYPE_CHECKING, Any

import rclpy
from action_msgs.msg import GoalStatus
from action_msgs.srv import CancelGoal
from nav2_msgs.action import NavigateToPose
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import BatteryState

from robot_agent.backends.port import GoalCancelled, GoalRejected, NavigationFailed, Progress
from vahr.domain import Pose
from vahr.errors import VahrError
from vahr.protocol import Battery

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.config import Nav2Settings
    from vahr.domain import Zone

log = logging.getLogger(__name__)

# How often a goal checks that its server is still there and still talking.
WATCH_PERIOD_S = 0.25
# How long a goal request waits for its answer before it is sent again (see `_send`).
RESEND_S = 1.0
# How long the spinning thread waits at most when nothing happens (every request wakes it):
# an idle robot-agent then costs about 0.2 % of a core instead of 0.8 % at 0.1 s.
SPIN_PERIOD_S = 1.0


class Nav2Backend:
    """Drives a ROS 2 robot through Nav2's NavigateToPose action server."""

    name = "nav2"
    observed_pose = True

    def __init__(self, settings: Nav2Settings, *, start: Pose) -> None:
        self.settings = settings
        self._pose = start
        self._context = Context()
        try:
            rclpy.init(context=self._context, domain_id=settings.domain_id)
            self._node = rclpy.create_node(settings.node_name, context=self._context)
        except Exception as err:  # rclpy raises its own RCLError and plain RuntimeErrors
            self._context.try_shutdown()
            raise VahrError(f"--backend nav2: cannot start a ROS 2 node ({err})") from err
        self._client = ActionClient(self._node, NavigateToPose, settings.action)
        self._active: Any = None  # the goal handle of the goal being driven, if any
        # The sends of a goal a stop overtook before the server's answer came: halt()'s.
        self._overtaken: list[Any] = []
        self._on_battery: Callable[[Battery], None] | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        if settings.battery_topic:
            self._node.create_subscription(
                BatteryState, settings.battery_topic, self._battery_state, qos_profile_sensor_data
            )
        self._executor = SingleThreadedExecutor(context=self._context)
        self._executor.add_node(self._node)
        self._stopping = threading.Event()
        self._spinner = threading.Thread(target=self._spin, name="nav2-spin", daemon=True)
        self._spinner.start()

    @property
    def pose(self) -> Pose:
        return self._pose

    def _spin(self) -> None:
        try:
            while not self._stopping.is_set() and self._context.ok():
                self._executor.spin_once(timeout_sec=SPIN_PERIOD_S)
        except ExternalShutdownException:
            pass  # the context was shut down under it

    def _call(self, call: Callable[[], Any]) -> asyncio.Future[Any]:
        """Run `call` on the spinning thread; its return value settles the future."""
        return _awaitable(asyncio.get_running_loop(), self._executor.create_task(call))

    # -- driving ------------------------------------------------------------------------

    async def go_to(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        loop = asyncio.get_running_loop()
        action = self.settings.action
        await self._wait_for_server()
        start, target = self._pose, zone.pose
        # The path is at least as long as the straight line, and Nav2 says how long it is.
        total = max(start.distance_to(target), 1e-6)
        heard = time.monotonic()
        fed = False

        def on_feedback(message: Any) -> None:  # on the spinning thread
            nonlocal heard, total, fed
            heard, fed = time.monotonic(), True
            feedback = message.feedback
            pose = _pose_of(feedback.current_pose.pose)
            remaining = float(feedback.distance_remaining)
            # Nav2 gives the path's length left; without it (0 before a path is planned),
            # the straight line to the goal is what is known.
            left = remaining if remaining > 0 else pose.distance_to(target)
            total = max(total, left)
            eta = _seconds(feedback.estimated_time_remaining)
            # Short of the goal, Nav2's zeros mean "not known yet", not "there".
            progress = Progress(
                fraction=min(max(1.0 - left / total, 0.0), 1.0),
                pose=pose,
                eta_s=eta if eta > 0 else None,
                distance_remaining_m=remaining if remaining > 0 else None,
            )
            loop.call_soon_threadsafe(self._progressed, progress, on_progress)

        handle = await self._send(self._goal(target), on_feedback, zone)
        if not handle.accepted:
            raise GoalRejected(f"Nav2's {action!r} server rejected the goal to {zone.id}")
        self._active = handle
        outcome = _awaitable(loop, await self._call(handle.get_result_async))
        heard = time.monotonic()
        try:
            while not outcome.done():
                await asyncio.wait({outcome}, timeout=WATCH_PERIOD_S)
                if outcome.done():
                    break
                if not await self._answer(self._call(self._client.server_is_ready), "answer"):
                    self._active = None  # no one is left to cancel it
                    raise NavigationFailed(
                        f"Nav2's {action!r} server went away during the goal to {zone.id}"
                    )
                silent = time.monotonic() - heard
                if silent > self.settings.feedback_timeout_s:
                    # A mute server may still drive the robot: the goal stays active, and
                    # the halt that follows a failure cancels it (within answer_timeout_s).
                    raise NavigationFailed(
                        f"Nav2's {action!r} server said nothing about the goal to {zone.id} "
                        f"for {self.settings.feedback_timeout_s:g} s"
                    )
            response = outcome.result()
        except asyncio.CancelledError:
            # Preempted or stopped: the cancel goes out now, and halt() waits for its answer.
            outcome.cancel()
            raise
        self._active = None
        self._ended(response.status, response.result, zone)
        if not fed:
            # Succeeded without a word on the way: the robot is where the goal was.
            self._pose = target
        on_progress(Progress(1.0, self._pose))

    async def _send(self, goal: Any, on_feedback: Callable[[Any], None], zone: Zone) -> Any:
        """Send `goal` until the server accepts or rejects it, for `answer_timeout_s`.

        A request is sent again after `RESEND_S` without an answer: DDS drops a request
        sent to a server that the graph already lists but whose endpoints are not matched
        yet (a bt_navigator just restarted while its dead predecessor's are still listed).
        Every request left unanswered is cancelled should the server accept it later; those
        of a goal that a stop or a preemption overtakes are halt()'s to wait for and cancel.
        """
        loop = asyncio.get_running_loop()
        deadline = time.monotonic() + self.settings.answer_timeout_s
        unanswered: list[Any] = []
        try:
            while True:
                sending = await self._call(
                    lambda: self._client.send_goal_async(goal, feedback_callback=on_feedback)
                )
                unanswered.append(sending)
                answer = _awaitable(loop, sending)
                left = deadline - time.monotonic()
                await asyncio.wait({answer}, timeout=max(min(RESEND_S, left), 0))
                if answer.done():
                    unanswered.remove(sending)
                    return answer.result()
                if time.monotonic() >= deadline:
                    raise NavigationFailed(
                        f"Nav2's {self.settings.action!r} server did not accept or reject the "
                        f"goal to {zone.id} within {self.settings.answer_timeout_s:g} s"
                    )
        except asyncio.CancelledError:
            self._overtaken, unanswered = unanswered, []
            raise
        finally:
            for pending in unanswered:
                pending.add_done_callback(_cancel_if_accepted)

    def _ended(self, status: int, result: Any, zone: Zone) -> None:
        """Raise what a goal's end means for the command; return when it succeeded."""
        if status == GoalStatus.STATUS_SUCCEEDED:
            return
        if status == GoalStatus.STATUS_ABORTED:
            text = result.error_msg or "no error_msg given"
            raise NavigationFailed(
                f"Nav2 aborted the goal to {zone.id} (error_code {result.error_code}): {text}"
            )
        if status == GoalStatus.STATUS_CANCELED:
            raise GoalCancelled(f"Nav2 cancelled the goal to {zone.id}")
        raise NavigationFailed(f"Nav2's goal to {zone.id} ended with status {status}")

    def _progressed(self, progress: Progress, on_progress: Callable[[Progress], None]) -> None:
        self._pose = progress.pose
        on_progress(progress)

    async def server_ready(self) -> bool:
        """Whether the action server is found now (DDS discovery has matched it)."""
        return bool(await self._answer(self._call(self._client.server_is_ready), "answer"))

    async def _wait_for_server(self) -> None:
        deadline = time.monotonic() + self.settings.server_timeout_s
        while not await self.server_ready():
            if time.monotonic() >= deadline:
                raise NavigationFailed(
                    f"no Nav2 action server {self.settings.action!r} answered within "
                    f"{self.settings.server_timeout_s:g} s (is bt_navigator running, in this "
                    "ROS_DOMAIN_ID?)"
                )
            await asyncio.sleep(0.05)

    async def _answer(self, pending: asyncio.Future[Any], what: str) -> Any:
        try:
            return await asyncio.wait_for(pending, self.settings.answer_timeout_s)
        except TimeoutError:
            raise NavigationFailed(
                f"Nav2's {self.settings.action!r} server did not {what} within "
                f"{self.settings.answer_timeout_s:g} s"
            ) from None

    def _goal(self, pose: Pose) -> Any:
        goal = NavigateToPose.Goal()
        goal.pose.header.frame_id = self.settings.frame
        goal.pose.header.stamp = self._node.get_clock().now().to_msg()
        goal.pose.pose.position.x = float(pose.x)
        goal.pose.pose.position.y = float(pose.y)
        goal.pose.pose.orientation.z = math.sin(pose.theta / 2)
        goal.pose.pose.orientation.w = math.cos(pose.theta / 2)
        goal.behavior_tree = self.settings.behavior_tree
        return goal

    async def operate_arm(self, zone: Zone) -> None:
        delay = (
            self.settings.loader_delay_s if zone.arm == "loader" else self.settings.unloader_delay_s
        )
        await asyncio.sleep(delay)

    async def halt(self) -> None:
        """Cancel the goal being driven, or the one a stop overtook on its way to being
        accepted, and wait (bounded) for Nav2 to confirm it."""
        handle, self._active = self._active, None
        if handle is None:
            handle = await self._accepted_overtaken()
        if handle is None:
            return
        loop = asyncio.get_running_loop()
        try:
            cancelling = await self._call(handle.cancel_goal_async)
            answer = await self._answer(_awaitable(loop, cancelling), "confirm the cancel")
        except NavigationFailed as err:
            log.warning("%s; the robot may still be driving", err)
            return
        # rclcpp's servers say ERROR_REJECTED; rclpy's leave ERROR_NONE with no goal.
        refused = answer.return_code == CancelGoal.Response.ERROR_REJECTED or (
            answer.return_code == CancelGoal.Response.ERROR_NONE and not answer.goals_canceling
        )
        if refused:
            log.warning(
                "Nav2's %r server refused to cancel the goal; the robot may still be driving",
                self.settings.action,
            )

    async def _accepted_overtaken(self) -> Any:
        """The handle of the goal a stop overtook, once Nav2 has accepted it (within
        `answer_timeout_s`); None if there is none or Nav2 rejected it. Its earlier sends
        are cancelled should the server accept them."""
        unanswered, self._overtaken = self._overtaken, []
        if not unanswered:
            return None
        *earlier, last = unanswered
        for pending in earlier:
            pending.add_done_callback(_cancel_if_accepted)
        answer = _awaitable(asyncio.get_running_loop(), last)
        try:
            handle = await self._answer(answer, "accept or reject the goal")
        except NavigationFailed as err:
            last.add_done_callback(_cancel_if_accepted)
            log.warning("%s; the robot may still be driving", err)
            return None
        except Exception:  # noqa: BLE001 - a send rclpy failed put no goal on the server
            return None
        return handle if handle.accepted else None

    def close_zones(self, closed: frozenset[str]) -> None:
        # Nav2 plans on the robot's own costmaps: a closed area is kept out there, by a
        # keepout filter (nav2_costmap_2d's KeepoutFilter with its filter mask), not by
        # this backend. The executor still refuses and ends tasks into a closed zone.
        return None

    async def leave(self, zone: Zone, on_progress: Callable[[Progress], None]) -> None:
        # Where to go out of an area is the robot's own planner's to say; see close_zones.
        return None

    async def close(self) -> None:
        await self.halt()
        self._stopping.set()
        # A task ends the spinning thread's wait (Executor.wake() does not: with nothing
        # ready, spin_once waits out its timeout).
        self._executor.create_task(lambda: None)
        await asyncio.to_thread(self._spinner.join, SPIN_PERIOD_S + 5)
        self._executor.shutdown()
        self._node.destroy_node()
        self._context.try_shutdown()

    # -- battery ------------------------------------------------------------------------

    def watch_battery(self, on_battery: Callable[[Battery], None]) -> None:
        self._loop = asyncio.get_running_loop()
        self._on_battery = on_battery

    def _battery_state(self, message: Any) -> None:  # on the spinning thread
        loop, on_battery = self._loop, self._on_battery
        percentage = float(message.percentage)
        if loop is None or on_battery is None or not math.isfinite(percentage):
            return  # nobody listens yet, or the robot does not know its charge (NaN)
        battery = Battery(
            percent=round(min(max(percentage, 0.0), 1.0) * 100),
            charging=message.power_supply_status == BatteryState.POWER_SUPPLY_STATUS_CHARGING,
        )
        loop.call_soon_threadsafe(on_battery, battery)


def _awaitable(loop: asyncio.AbstractEventLoop, pending: Any) -> asyncio.Future[Any]:
    """An asyncio future settled when the rclpy future `pending` is (on any thread)."""
    future: asyncio.Future[Any] = loop.create_future()

    def settle(done: Any) -> None:
        if future.done():
            return
        error = done.exception()
        if error is not None:
            future.set_exception(error)
        else:
            future.set_result(done.result())

    pending.add_done_callback(lambda done: loop.call_soon_threadsafe(settle, done))
    return future


def _cancel_if_accepted(sending: Any) -> None:  # on the spinning thread
    handle = sending.result() if sending.exception() is None else None
    if handle is not None and handle.accepted:
        handle.cancel_goal_async()


def _seconds(duration: Any) -> float:
    return float(duration.sec) + float(duration.nanosec) / 1e9


def _pose_of(pose: Any) -> Pose:
    q = pose.orientation
    theta = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
    return Pose(pose.position.x, pose.position.y, theta)
