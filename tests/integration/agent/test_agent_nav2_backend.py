"""The nav2 backend against real rclpy and Fast DDS: what only a ROS 2 robot does.

The server is the stand-in bt_navigator (tests/support/nav2_stand_in.py, a real rclpy
NavigateToPose action server, not Nav2) in a process of its own; the backend is the agent's,
in this process, or a real `robot-agent run --backend nav2` on a real mosquitto. What every
backend does alike (navigate, deliver, stop, preempt, abort) is in test_backend_conformance.
"""

from __future__ import annotations

import asyncio
import math
import signal
import time
from typing import TYPE_CHECKING, Any

import pytest

from robot_agent.clock import ScaledClock
from robot_agent.config import ExecutorSettings, Nav2Settings
from robot_agent.core.executor import Executor
from tests.support.nav2 import HAS_ROS2, WITHOUT_ROS2, Nav2StandIn, next_domain_id
from tests.unit.agent.conftest import Recorder
from vahr.protocol import Battery, new_command

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.twin.broker import Mosquitto

pytestmark = [pytest.mark.ros2, pytest.mark.skipif(not HAS_ROS2, reason=WITHOUT_ROS2)]

# sensor_msgs/BatteryState's power_supply_status values.
CHARGING, DISCHARGING = 1, 2


def nav2_robot(fleet: Fleet, domain_id: int, **settings: Any) -> tuple[Executor, Recorder]:
    """An executor on a Nav2Backend, reporting every feedback; call it on the event loop."""
    from robot_agent.backends.nav2 import Nav2Backend

    backend = Nav2Backend(
        Nav2Settings(
            domain_id=domain_id, **{"loader_delay_s": 0.05, "unloader_delay_s": 0.05, **settings}
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
        settings=ExecutorSettings(stuck_after_s=30, progress_interval_s=0, progress_step=0),
    )
    backend.watch_battery(executor.report_battery)
    return executor, recorder


async def found_by(executor: Executor, timeout_s: float = 30.0) -> None:
    """Wait until the robot's action client has discovered the server."""
    from robot_agent.backends.nav2 import Nav2Backend

    backend = executor.backend
    assert isinstance(backend, Nav2Backend)
    async with asyncio.timeout(timeout_s):
        while not await backend.server_ready():
            await asyncio.sleep(0.05)


def cmd(action: str, params: dict[str, Any] | None, command_id: str) -> Any:
    return new_command(action, params, source="console", command_id=command_id)


@pytest.fixture
def own_stand_in(tmp_path: Path, nav2_stand_in: Nav2StandIn) -> Iterator[Nav2StandIn]:
    """A stand-in of the test's own, in a domain of its own, not yet started (the module's
    stand-in is asked for only so that the ROS environment is set)."""
    stand_in = Nav2StandIn(tmp_path / "own-stand-in", domain_id=next_domain_id())
    yield stand_in
    stand_in.stop()


async def test_feedback_becomes_progress_with_eta_and_distance_and_moves_the_shadow_pose(
    fleet: Fleet, nav2_stand_in: Nav2StandIn
) -> None:
    nav2_stand_in.plan()
    executor, rec = nav2_robot(fleet, nav2_stand_in.domain_id)
    try:
        executor.execute(cmd("navigate", {"zone": "B"}, "g1"))
        await executor.wait_idle()
    finally:
        await executor.close()
    progress = [e for e in rec.events if e.event == "progress" and e.command_id == "g1"]
    assert len(progress) >= 5
    # Nav2's own estimates, as it sent them: time and distance left shrink on the way
    etas = [e.eta_s for e in progress]
    distances = [e.distance_remaining_m for e in progress]
    assert None not in etas and etas == sorted(etas, reverse=True)  # type: ignore[type-var]
    assert None not in distances and distances == sorted(distances, reverse=True)  # type: ignore[type-var]
    # and the shadow's pose followed current_pose, from the start to B
    xs = [state.pose.x for state in rec.states if state.pose is not None]
    on_the_way = [x for x in xs if 1.0 < x < 9.0]
    assert len(on_the_way) >= 3 and on_the_way == sorted(on_the_way)
    assert rec.states[-1].pose is not None and rec.states[-1].pose.x == 9.0


async def test_feedback_with_only_a_pose_still_reports_the_way(
    fleet: Fleet, own_stand_in: Nav2StandIn
) -> None:
    # Given a server whose feedback carries current_pose and no distance or time left
    await asyncio.to_thread(own_stand_in.start)
    own_stand_in.plan({"mode": "succeed", "pose_only": True})
    executor, rec = nav2_robot(fleet, own_stand_in.domain_id)
    try:
        executor.execute(cmd("navigate", {"zone": "B"}, "g3"))
        await executor.wait_idle()
    finally:
        await executor.close()
    # Then the way is reported from the poses, and no estimate is made up
    progress = [e for e in rec.events if e.event == "progress"]
    fractions = [e.progress for e in progress]
    assert len(progress) >= 5 and fractions == sorted(fractions)
    assert {(e.eta_s, e.distance_remaining_m) for e in progress} == {(None, None)}
    assert rec.kinds("g3")[-2:] == ["arrived", "done"]


async def test_goals_go_to_the_configured_action_in_the_configured_frame_and_tree(
    fleet: Fleet, own_stand_in: Nav2StandIn
) -> None:
    own_stand_in.action = "/placebot1/navigate_to_pose"
    own_stand_in.start()
    executor, rec = nav2_robot(
        fleet,
        own_stand_in.domain_id,
        action="/placebot1/navigate_to_pose",
        frame="warehouse",
        behavior_tree="navigate_w_replanning_and_recovery.xml",
    )
    try:
        executor.execute(cmd("navigate", {"zone": "LOADING"}, "g2"))
        await executor.wait_idle()
    finally:
        await executor.close()
    goal = own_stand_in.wait_for("goal")
    assert (goal["x"], goal["y"], goal["frame"]) == (1.5, 4.0, "warehouse")
    # The yaw as a quaternion: -pi and pi are one heading.
    assert abs(math.remainder(goal["theta"] - 3.1416, math.tau)) < 1e-4
    assert goal["behavior_tree"] == "navigate_w_replanning_and_recovery.xml"
    assert rec.kinds("g2")[-1] == "done"


async def test_a_goal_the_server_rejects_ends_the_command_rejected(
    fleet: Fleet, nav2_stand_in: Nav2StandIn
) -> None:
    nav2_stand_in.plan({"mode": "reject"})
    executor, rec = nav2_robot(fleet, nav2_stand_in.domain_id)
    try:
        executor.execute(cmd("navigate", {"zone": "B"}, "r1"))
        await executor.wait_idle()
    finally:
        await executor.close()
    reason = "Nav2's 'navigate_to_pose' server rejected the goal to B"
    assert rec.kinds("r1") == ["accepted", "rejected"]
    assert rec.first("rejected", "r1").reason == reason
    final = rec.states[-1]
    assert final.status == "idle" and final.last_command is not None
    assert (final.last_command.result, final.last_command.reason) == ("rejected", reason)


async def test_a_goal_cancelled_by_another_client_ends_the_command_cancelled(
    fleet: Fleet, nav2_stand_in: Nav2StandIn
) -> None:
    nav2_stand_in.plan({"mode": "cancel_elsewhere"})
    executor, rec = nav2_robot(fleet, nav2_stand_in.domain_id)
    try:
        executor.execute(cmd("navigate", {"zone": "C"}, "x1"))
        await executor.wait_idle()
    finally:
        await executor.close()
    assert rec.kinds("x1")[-1] == "cancelled"
    assert rec.first("cancelled", "x1").reason == "Nav2 cancelled the goal to C"
    final = rec.states[-1]
    assert final.status == "idle" and final.last_command is not None
    assert final.last_command.result == "cancelled"


async def test_a_goal_that_never_answers_fails_after_the_feedback_timeout(
    fleet: Fleet, nav2_stand_in: Nav2StandIn
) -> None:
    seen = len(nav2_stand_in.seen("cancel_requested"))
    nav2_stand_in.plan({"mode": "stall"})
    executor, rec = nav2_robot(fleet, nav2_stand_in.domain_id, feedback_timeout_s=1)
    try:
        began = time.monotonic()
        executor.execute(cmd("navigate", {"zone": "A"}, "t1"))
        await executor.wait_idle()
        took = time.monotonic() - began
    finally:
        await executor.close()
    reason = "Nav2's 'navigate_to_pose' server said nothing about the goal to A for 1 s"
    assert rec.first("failed", "t1").reason == reason
    # Not before the timeout; the upper bound only says it did not hang (a loaded machine
    # adds the cancel's round trip and the spin period to the timeout).
    assert 1 <= took < 10, (took, nav2_stand_in.log()[-6:], time.monotonic())
    # and the mute goal was cancelled on the server, which still listens, before it failed
    nav2_stand_in.wait_for("cancel_requested", seen + 1, timeout_s=0)


# A stop while the robot drives the goal, and one that overtakes the goal's acceptance on its
# way to the robot (the server takes a second to accept): either way the robot asks Nav2 to
# cancel the goal and waits for the answer.
@pytest.mark.parametrize(
    ("accept_delay_s", "stop_after"), [(0.0, "accepted"), (1.0, "goal")],
    ids=["driving", "before-the-acceptance"],
)  # fmt: skip
async def test_a_cancel_nav2_refuses_is_logged_as_such(
    fleet: Fleet,
    own_stand_in: Nav2StandIn,
    caplog: pytest.LogCaptureFixture,
    accept_delay_s: float,
    stop_after: str,
) -> None:
    await asyncio.to_thread(own_stand_in.start)
    plan = {"mode": "stall", "refuse_cancel": True, "accept_delay_s": accept_delay_s}
    own_stand_in.plan(plan)
    # The refusal's answer may take seconds on a loaded machine (discovery of the cancel
    # service): the robot waits for it here rather than log that none came.
    executor, rec = nav2_robot(
        fleet, own_stand_in.domain_id, feedback_timeout_s=30, answer_timeout_s=20
    )
    try:
        executor.execute(cmd("navigate", {"zone": "A"}, "z1"))
        await asyncio.to_thread(own_stand_in.wait_for, stop_after)
        # When a stop comes and Nav2 refuses to cancel the goal
        executor.execute(cmd("stop", None, "z2"))
        await executor.wait_idle()
    finally:
        await executor.close()
    own_stand_in.wait_for("cancel_refused", timeout_s=0)
    # Then the stop ends as a stop does, and the log says the robot may still be driving
    assert rec.kinds("z2") == ["accepted", "stopped", "done"]
    assert (
        "Nav2's 'navigate_to_pose' server refused to cancel the goal; the robot may still be "
        "driving"
    ) in caplog.messages


async def test_without_a_server_a_goal_fails_in_bounded_time_and_works_once_it_is_there(
    fleet: Fleet, own_stand_in: Nav2StandIn
) -> None:
    # Given no action server in the robot's domain
    # (a server that starts after its client is found in about 1.5 s here)
    executor, rec = nav2_robot(fleet, own_stand_in.domain_id, server_timeout_s=3)
    try:
        began = time.monotonic()
        executor.execute(cmd("navigate", {"zone": "B"}, "o1"))
        await executor.wait_idle()
        took = time.monotonic() - began
        # Then the goal fails within the server timeout, with a reason that says so
        reason = rec.first("failed", "o1").reason
        assert reason is not None and reason.startswith(
            "no Nav2 action server 'navigate_to_pose' answered within 3 s"
        )
        assert took < 5
        # When bt_navigator comes up and the robot has found it (discovery takes about 1.5 s
        # here, longer on a busy machine: more than the 3 s of this robot's timeout beside
        # the whole suite), the same robot's next goal is served
        await asyncio.to_thread(own_stand_in.start)
        await found_by(executor)
        executor.execute(cmd("navigate", {"zone": "B"}, "o2"))
        await executor.wait_idle()
        assert rec.kinds("o2")[-1] == "done", rec.events[-1]
    finally:
        await executor.close()


async def test_a_server_that_dies_mid_goal_fails_the_goal_and_its_successor_is_found(
    fleet: Fleet, own_stand_in: Nav2StandIn
) -> None:
    await asyncio.to_thread(own_stand_in.start)
    own_stand_in.plan({"mode": "die", "steps": 20, "step_s": 0.05})
    # (a server restarted while its predecessor is still listed is matched in 1-2 s here)
    executor, rec = nav2_robot(
        fleet, own_stand_in.domain_id, feedback_timeout_s=1, answer_timeout_s=4
    )
    try:
        executor.execute(cmd("navigate", {"zone": "D"}, "k1"))
        await executor.wait_idle()
        # The goal failed: the server went away, or (a crash says no goodbye) went silent
        reason = rec.first("failed", "k1").reason
        assert reason in (
            "Nav2's 'navigate_to_pose' server went away during the goal to D",
            "Nav2's 'navigate_to_pose' server said nothing about the goal to D for 1 s",
        )
        assert own_stand_in.wait_exit() == 3
        # When it is restarted and found, the next goal works
        own_stand_in.plan()
        await asyncio.to_thread(own_stand_in.start)
        await found_by(executor)
        executor.execute(cmd("navigate", {"zone": "D"}, "k2"))
        await executor.wait_idle()
        assert rec.kinds("k2")[-1] == "done", rec.events[-1].reason
    finally:
        await executor.close()


async def test_the_robot_s_battery_state_reaches_the_shadow(
    fleet: Fleet, nav2_stand_in: Nav2StandIn
) -> None:
    executor, rec = nav2_robot(fleet, nav2_stand_in.domain_id)
    # A connected robot: before it connects a reading is only recorded (its whole state goes
    # out on connecting).
    executor.set_connected(True)
    connected = len(rec.states)

    async def battery_becomes(expected: Battery) -> None:
        async with asyncio.timeout(10):
            while executor.state.battery != expected:
                await asyncio.sleep(0.02)

    try:
        nav2_stand_in.battery(0.42, CHARGING)
        await battery_becomes(Battery(percent=42, charging=True))
        nav2_stand_in.battery(0.418, DISCHARGING)
        await battery_becomes(Battery(percent=42, charging=False))
        # A charge the robot does not know (NaN) changes nothing
        nav2_stand_in.battery(float("nan"), DISCHARGING)
        await asyncio.sleep(0.5)
        assert executor.state.battery == Battery(percent=42, charging=False)
    finally:
        await executor.close()
        (nav2_stand_in.control / "battery.json").unlink(missing_ok=True)
    # The shadow heard of each change once (the robot publishes ten readings a second)
    batteries = [s.battery for s in rec.states[connected:]]
    assert batteries == [Battery(42, True), Battery(42, False)]


def test_robot_agent_run_with_the_nav2_backend_drives_nav2_from_mqtt(
    own_stand_in: Nav2StandIn, mosquitto: Mosquitto, tmp_path: Path
) -> None:
    from tests.integration.agent.harness import AgentProcess, ShadowResponder, WireTap, command

    # A stand-in of its own, so that its robot starts where placebot1 does.
    stand_in = own_stand_in.start()
    port = mosquitto.config.plain_port or 0
    tap, shadows = WireTap(port), ShadowResponder(port)
    config = tmp_path / "nav2.yaml"
    config.write_text(
        f"nav2:\n  domain_id: {stand_in.domain_id}\n  loader_delay_s: 0.05\n"
        "  unloader_delay_s: 0.05\n  feedback_timeout_s: 10\n"
        "executor:\n  progress_interval_s: 0\n  progress_step: 0\n"
    )
    stand_in.plan()
    stand_in.battery(0.8, DISCHARGING)
    agent = AgentProcess(
        "--thing",
        "placebot1",
        "--broker",
        str(mosquitto.plain_url),
        "--backend",
        "nav2",
        "--config",
        str(config),
        state_dir=tmp_path / "state",
        log_file=tmp_path / "agent.log",
    )
    try:
        tap.reported("placebot1", lambda r: r["connected"] is True, timeout_s=20)
        goals = len(stand_in.seen("goal"))
        # When a navigate command arrives over MQTT
        tap.publish("vahr/robots/placebot1/cmd", command("nav-b", "navigate", {"zone": "B"}))
        # Then Nav2 gets a goal at B's pose in map, and the command is done
        state = tap.reported(
            "placebot1",
            lambda r: (
                (r["last_command"] or {})
                == {
                    "id": "nav-b",
                    "action": "navigate",
                    "result": "done",
                    "reason": None,
                    "zone": "B",
                }
            ),
        )
        goal = stand_in.seen("goal")[goals]
        assert (goal["x"], goal["y"], goal["frame"]) == (9.0, 5.0, "map")
        assert (state["zone"], state["pose"]) == ("B", {"x": 9.0, "y": 5.0, "theta": 0.0})
        # with the shadow's pose following the feedback on the way, and the battery reported
        poses = [u["state"]["reported"]["pose"] for u in tap.shadow_updates("placebot1")]
        xs = [pose["x"] for pose in poses if pose]
        assert len([x for x in xs if 1.0 < x < 9.0]) >= 3, poses
        assert state["battery"] == {"percent": 80, "charging": False}
        # When Nav2 aborts the next goal, the command fails with Nav2's message
        stand_in.plan({"mode": "abort", "error_code": 204, "error_msg": "no valid path found"})
        tap.publish("vahr/robots/placebot1/cmd", command("nav-d", "navigate", {"zone": "D"}))
        state = tap.reported(
            "placebot1",
            lambda r: (
                (r["last_command"] or {}).get("id") == "nav-d"
                and r["last_command"]["result"] == "failed"
            ),
        )
        assert (
            state["last_command"]["reason"]
            == "Nav2 aborted the goal to D (error_code 204): no valid path found"
        )
        assert state["status"] == "error"
        # When a stop arrives while a goal runs, the goal is cancelled and the robot stopped
        stand_in.plan({"mode": "stall"})
        cancels = len(stand_in.seen("canceled"))
        accepted = len(stand_in.seen("accepted"))
        tap.publish("vahr/robots/placebot1/cmd", command("nav-a", "navigate", {"zone": "A"}))
        stand_in.wait_for("accepted", accepted + 1)
        tap.publish("vahr/robots/placebot1/cmd", command("halt", "stop", None))
        state = tap.reported("placebot1", lambda r: (r["last_command"] or {}).get("id") == "halt")
        assert (state["status"], state["last_command"]["result"]) == ("stopped", "done")
        stand_in.wait_for("canceled", cancels + 1, timeout_s=5)
        tap.event("placebot1", "cancelled", "nav-a")
        # and it stops cleanly on SIGTERM
        assert agent.stop(signal.SIGTERM, timeout_s=15) == 0, agent.log()
    finally:
        if agent.process.poll() is None:
            agent.kill()
        tap.close()
        shadows.close()
