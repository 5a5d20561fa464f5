"""The executor on its own: every action of docs/protocol.md on a fast simulated robot."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from robot_agent.backends.port import Progress
from robot_agent.config import ExecutorSettings, SimSettings
from tests.unit.agent.conftest import make_executor, until_moved
from vahr.domain import Pose
from vahr.protocol import Event, new_command, utc_now

if TYPE_CHECKING:
    from vahr.domain import Fleet


def cmd(action: str, params: dict[str, object] | None = None, command_id: str | None = None):  # type: ignore[no-untyped-def]
    return new_command(action, params, source="console", command_id=command_id)


async def test_navigate_reports_navigating_then_arrives_idle_in_the_zone(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet)
    # When
    executor.execute(cmd("navigate", {"zone": "B"}, "n1"))
    await executor.wait_idle()
    # Then
    assert rec.kinds("n1")[0] == "accepted"
    assert rec.kinds("n1")[-2:] == ["arrived", "done"]
    assert "progress" in rec.kinds("n1")
    assert (
        rec.states[0].last_command is not None and rec.states[0].last_command.result == "accepted"
    )
    assert any(s.status == "navigating" for s in rec.states)
    final = rec.states[-1]
    assert (final.status, final.zone, final.task) == ("idle", "B", None)
    assert final.last_command is not None and (
        final.last_command.id,
        final.last_command.result,
    ) == ("n1", "done")
    assert backend.pose.distance_to(fleet.zone("B").pose) < 1e-6


async def test_each_state_is_published_once_and_only_on_change(fleet: Fleet) -> None:
    # Given a robot reporting progress every simulated second (the local stack's rate)
    executor, rec, _ = make_executor(
        fleet,
        settings=ExecutorSettings(stuck_after_s=120, progress_interval_s=1, progress_step=0),
    )
    executor.execute(cmd("navigate", {"zone": "A"}, "n1"))
    await executor.wait_idle()
    for before, after in zip(rec.states, rec.states[1:], strict=False):
        assert before != after
    # Progress ticks are events, not shadow updates.
    assert len(rec.states) < 8 < len(rec.events)


async def test_deliver_loads_at_loading_then_unloads_in_the_zone(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet)
    executor.execute(cmd("deliver", {"zone": "C"}, "d1"))
    await executor.wait_idle()
    milestones = [
        (e.event, e.zone) for e in rec.events if e.event in {"arrived", "loaded", "delivered"}
    ]
    assert milestones == [
        ("arrived", "LOADING"),
        ("loaded", "LOADING"),
        ("arrived", "C"),
        ("delivered", "C"),
    ]
    statuses = [s.status for s in rec.states]
    assert statuses.index("loading") < statuses.index("unloading")
    assert any(s.cargo for s in rec.states)
    final = rec.states[-1]
    assert (final.status, final.zone, final.cargo) == ("idle", "C", False)
    assert final.last_command is not None and final.last_command.result == "done"


async def test_by_default_a_drive_reports_progress_at_most_every_5_s_and_per_quarter(
    fleet: Fleet,
) -> None:
    # Given a robot with the default (AWS) reporting rate, and a drive of 16.5 simulated
    # seconds (placebot1's start to zone B, 8.25 m at 0.5 m/s)
    executor, rec, _ = make_executor(fleet)
    # When it drives there
    executor.execute(cmd("navigate", {"zone": "B"}, "far"))
    await executor.wait_idle()
    # Then a few progress reports went out (16.5 s allow three 5-second gaps), each at
    # least a quarter of the way after the one before, and the drive still ends arrived, done
    progress = [e for e in rec.events if e.event == "progress"]
    assert 1 <= len(progress) <= 3
    fractions = [0.0] + [e.progress or 0.0 for e in progress]
    assert all(b - a >= 0.25 - 1e-6 for a, b in zip(fractions, fractions[1:], strict=False))
    assert rec.kinds("far")[-2:] == ["arrived", "done"]


async def test_the_time_bound_alone_limits_progress_to_one_every_interval(fleet: Fleet) -> None:
    # Given a robot reporting at most every 8 simulated seconds, whatever the way covered
    executor, rec, _ = make_executor(
        fleet, settings=ExecutorSettings(stuck_after_s=120, progress_interval_s=8, progress_step=0)
    )
    # When it drives 16.5 simulated seconds
    executor.execute(cmd("navigate", {"zone": "B"}, "far"))
    await executor.wait_idle()
    # Then it reported twice at most, 8 s (4 m) of driving apart
    progress = [e.progress or 0.0 for e in rec.events if e.event == "progress"]
    assert 1 <= len(progress) <= 2
    assert all(b - a >= 4.0 / 8.25 - 0.01 for a, b in zip(progress, progress[1:], strict=False))


async def test_a_short_drive_reports_no_progress_by_default_but_does_locally(
    fleet: Fleet,
) -> None:
    # Given the same short drive (1.1 m, 2.2 simulated seconds) at both reporting rates
    # (at x20: a starved event loop must not make simulated seconds pass unnoticed)
    aws, aws_rec, _ = make_executor(fleet, settings=ExecutorSettings(stuck_after_s=120), speed=20)
    local, local_rec, _ = make_executor(
        fleet,
        settings=ExecutorSettings(stuck_after_s=120, progress_interval_s=0.5, progress_step=0),
        speed=20,
    )
    # When each drives to the loading zone
    for executor in (aws, local):
        executor.execute(cmd("navigate", {"zone": "LOADING"}, "near"))
        await executor.wait_idle()
    # Then on AWS's rate only what changed is said; locally the drive is reported as it goes
    assert aws_rec.kinds("near") == ["accepted", "arrived", "loaded", "done"]
    assert local_rec.kinds("near").count("progress") >= 2


async def test_a_new_motion_command_preempts_and_the_old_task_ends_cancelled(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet, speed=50)
    executor.execute(cmd("deliver", {"zone": "A"}, "old"))
    await until_moved(backend)
    executor.execute(cmd("navigate", {"zone": "D"}, "new"))
    await executor.wait_idle()
    assert rec.kinds("old")[-1] == "cancelled"
    assert rec.first("cancelled", "old").reason == "preempted by navigate new"
    assert "delivered" not in rec.kinds("old")
    assert rec.kinds("new")[-1] == "done"
    assert rec.states[-1].zone == "D"
    assert rec.states[-1].last_command is not None and rec.states[-1].last_command.id == "new"


async def test_stop_preempts_everything_and_halts_where_the_robot_is(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet, speed=50)
    executor.execute(cmd("navigate", {"zone": "A"}, "go"))
    await until_moved(backend)
    executor.execute(cmd("stop", None, "halt"))
    await executor.wait_idle()
    where = backend.pose
    assert rec.kinds("go")[-1] == "cancelled"
    assert rec.kinds("halt") == ["accepted", "stopped", "done"]
    final = rec.states[-1]
    assert final.status == "stopped" and final.task is None
    assert final.last_command is not None and (
        final.last_command.id,
        final.last_command.result,
    ) == ("halt", "done")
    # The robot does not keep driving after the stop.
    await executor.clock.sleep(5)
    assert backend.pose == where


async def test_ping_acknowledges_without_disturbing_a_running_task(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, speed=100)
    executor.execute(cmd("navigate", {"zone": "B"}, "nav"))
    states_before = len(rec.states)
    executor.execute(cmd("ping", None, "p1"))
    assert rec.kinds("p1") == ["accepted", "done"]
    # One shadow update says it: the ping was accepted and done at once.
    assert len(rec.states) == states_before + 1
    last = rec.states[-1].last_command
    assert last is not None and (last.id, last.result) == ("p1", "done")
    await executor.wait_idle()
    assert rec.kinds("nav")[-1] == "done"


async def test_no_progress_for_the_stuck_time_reports_stuck_and_fails(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(
        fleet, sim=SimSettings(stuck_zones=("D",)), settings=ExecutorSettings(stuck_after_s=5)
    )
    executor.execute(cmd("navigate", {"zone": "D"}, "s1"))
    await executor.wait_idle()
    stuck = rec.first("stuck", "s1")
    assert stuck.reason == "no progress towards D for 5 s"
    assert rec.kinds("s1")[-1] == "failed"
    final = rec.states[-1]
    assert final.status == "stuck"
    assert final.last_command is not None and final.last_command.result == "failed"
    assert final.last_command.reason == "stuck: no progress towards D for 5 s"


async def test_an_aborted_goal_fails_with_the_backend_reason(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet)
    backend.inject_failure("the costmap is blocked")
    executor.execute(cmd("navigate", {"zone": "A"}, "f1"))
    await executor.wait_idle()
    failed = rec.first("failed", "f1")
    assert failed.reason == "goal to A aborted: the costmap is blocked"
    assert rec.states[-1].status == "error"
    assert (
        rec.states[-1].last_command is not None and rec.states[-1].last_command.result == "failed"
    )


async def test_sequential_delivery_waits_for_the_peer_then_delivers(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, thing="placebot2")
    executor.execute(cmd("sequential_delivery", {"zone": "B", "after": "placebot1"}, "q1"))
    await rec.until("waiting", "q1")
    assert rec.states[-1].status == "waiting"
    assert "loaded" not in rec.kinds("q1")
    executor.peer_event(Event(event="delivered", thing="placebot1", at=utc_now(), zone="A"))
    await executor.wait_idle()
    assert rec.kinds("q1")[-2:] == ["delivered", "done"]


async def test_sequential_delivery_counts_a_delivery_seen_before_the_command(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, thing="placebot2")
    executor.peer_event(Event(event="delivered", thing="placebot1", at=utc_now(), zone="A"))
    executor.execute(cmd("sequential_delivery", {"zone": "B", "after": "placebot1"}, "q2"))
    await executor.wait_idle()
    assert "waiting" not in rec.kinds("q2")
    assert rec.kinds("q2")[-1] == "done"


async def test_sequential_delivery_times_out_with_a_reason(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(
        fleet, thing="placebot2", settings=ExecutorSettings(sequential_timeout_s=20)
    )
    executor.execute(cmd("sequential_delivery", {"zone": "B", "after": "placebot1"}, "q3"))
    await executor.wait_idle()
    assert rec.first("failed", "q3").reason == "placebot1 did not deliver within 20 s"
    final = rec.states[-1]
    assert final.status == "idle"
    assert final.last_command is not None and final.last_command.result == "failed"


async def test_sequential_delivery_after_itself_is_rejected(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, thing="placebot1")
    executor.execute(cmd("sequential_delivery", {"zone": "B", "after": "placebot1"}, "q4"))
    assert rec.kinds("q4") == ["rejected"]
    assert rec.states[-1].last_command is not None
    assert rec.states[-1].last_command.reason == "params.after: a robot cannot wait for itself"


async def test_stop_while_waiting_for_a_peer_cancels_the_wait(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, thing="placebot2")
    executor.execute(cmd("sequential_delivery", {"zone": "B", "after": "placebot1"}, "wait"))
    await rec.until("waiting", "wait")
    executor.execute(cmd("stop", None, "halt"))
    await executor.wait_idle()
    assert rec.kinds("wait")[-1] == "cancelled"
    # A late delivery by the peer no longer starts anything.
    executor.peer_event(Event(event="delivered", thing="placebot1", at=utc_now(), zone="A"))
    await asyncio.sleep(0.05)
    assert "loaded" not in rec.kinds("wait")
    assert rec.states[-1].status == "stopped"


async def test_a_delivery_cut_short_after_loading_keeps_the_cargo_for_the_next_one(
    fleet: Fleet,
) -> None:
    executor, rec, _ = make_executor(fleet, speed=50)
    executor.execute(cmd("deliver", {"zone": "A"}, "first"))
    await rec.until("loaded", "first", timeout_s=10)
    executor.execute(cmd("deliver", {"zone": "D"}, "second"))
    await executor.wait_idle()
    assert rec.kinds("first")[-1] == "cancelled"
    assert "loaded" not in rec.kinds("second")
    assert rec.first("delivered", "second").zone == "D"
    assert rec.states[-1].cargo is False


async def test_navigating_to_the_zone_it_is_in_arrives_at_once(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet)
    executor.execute(cmd("navigate", {"zone": "C"}, "go"))
    await executor.wait_idle()
    executor.execute(cmd("navigate", {"zone": "C"}, "again"))
    await executor.wait_idle()
    assert rec.kinds("again") == ["accepted", "arrived", "done"]


async def test_close_cancels_the_running_task(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet, speed=20)
    executor.execute(cmd("navigate", {"zone": "A"}, "going"))
    await until_moved(backend)
    await executor.close()
    assert rec.first("cancelled", "going").reason == "the agent is shutting down"
    final = rec.states[-1]
    assert final.status == "stopped"
    assert final.last_command is not None and final.last_command.result == "cancelled"


async def test_a_burst_of_commands_runs_only_the_last_and_never_two_at_once(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet, speed=50)
    # When three motion commands arrive back to back (no time in between)
    executor.execute(cmd("navigate", {"zone": "A"}, "b1"))
    executor.execute(cmd("deliver", {"zone": "B"}, "b2"))
    executor.execute(cmd("navigate", {"zone": "D"}, "b3"))
    await executor.wait_idle()
    # Then the first two end cancelled without moving, and only the last one drives
    assert rec.kinds("b1") == ["accepted", "cancelled"]
    assert rec.kinds("b2") == ["accepted", "cancelled"]
    assert rec.kinds("b3")[-2:] == ["arrived", "done"]
    assert rec.states[-1].zone == "D" and backend.pose == fleet.zone("D").pose
    await asyncio.sleep(0.1)
    assert backend.pose == fleet.zone("D").pose


async def test_close_during_a_burst_returns_promptly(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, speed=1)
    for index in range(20):
        executor.execute(cmd("navigate", {"zone": "ABCD"[index % 4]}, f"c{index}"))
    async with asyncio.timeout(2):
        await executor.close()
    assert rec.kinds("c19")[-1] == "cancelled"


class ThreadedFeedbackBackend:
    """A backend whose feedback arrives from another thread, as rospy's does."""

    name = "threaded"
    observed_pose = True

    def __init__(self, start: Pose) -> None:
        self.pose = start

    async def go_to(self, zone, on_progress):  # type: ignore[no-untyped-def]
        import threading

        loop = asyncio.get_running_loop()
        stop = threading.Event()

        def feedback() -> None:
            fraction = 0.0
            while not stop.is_set():
                fraction += 0.001
                loop.call_soon_threadsafe(on_progress, Progress(fraction, Pose(fraction, 0.0)))
                stop.wait(0.0005)

        thread = threading.Thread(target=feedback)
        thread.start()
        try:
            await asyncio.sleep(30)
        finally:
            # Like actionlib, the goal is cancelled but feedback already queued still lands.
            await asyncio.sleep(0.01)
            stop.set()
            thread.join(1)

    async def operate_arm(self, zone):  # type: ignore[no-untyped-def]
        return None

    async def halt(self) -> None:
        return None

    async def close(self) -> None:
        return None


async def test_no_progress_is_reported_for_a_task_after_its_cancelled_event(fleet: Fleet) -> None:
    from robot_agent.clock import ScaledClock
    from robot_agent.core.executor import Executor
    from tests.unit.agent.conftest import Recorder

    rec = Recorder()
    executor = Executor(
        thing="placebot1",
        fleet=fleet,
        backend=ThreadedFeedbackBackend(fleet.robot("placebot1").start),
        clock=ScaledClock(1),
        publish_state=rec.states.append,
        publish_event=rec.events.append,
        settings=ExecutorSettings(progress_interval_s=0, progress_step=0),
    )
    executor.execute(cmd("navigate", {"zone": "A"}, "first"))
    await rec.until("progress", "first")
    executor.execute(cmd("stop", None, "halt"))
    await executor.wait_idle()
    await asyncio.sleep(0.05)
    kinds = rec.kinds("first")
    assert kinds[-1] == "cancelled", kinds[-5:]


async def test_the_zones_arms_act_on_a_robot_that_navigates_there(fleet: Fleet) -> None:
    # Given an empty robot, as on the paper's floor where arms act on arrival
    executor, rec, _ = make_executor(fleet)
    # When it is only navigated: to the loading zone, then to zone B, then to zone C
    executor.execute(cmd("navigate", {"zone": "LOADING"}, "to-loading"))
    await executor.wait_idle()
    executor.execute(cmd("navigate", {"zone": "B"}, "to-b"))
    await executor.wait_idle()
    executor.execute(cmd("navigate", {"zone": "C"}, "to-c"))
    await executor.wait_idle()
    # Then the loader loaded it on arrival and B's arm unloaded it; C's arm had nothing to take
    milestones = [
        (e.event, e.zone, e.command_id)
        for e in rec.events
        if e.event in {"arrived", "loaded", "delivered"}
    ]
    assert milestones == [
        ("arrived", "LOADING", "to-loading"),
        ("loaded", "LOADING", "to-loading"),
        ("arrived", "B", "to-b"),
        ("delivered", "B", "to-b"),
        ("arrived", "C", "to-c"),
    ]
    final = rec.states[-1]
    assert (final.status, final.zone, final.cargo) == ("idle", "C", False)
