"""The command executor: one robot's state machine, free of any transport.

`execute(command)` is called on the event loop for every decoded, de-duplicated command.
The executor decides what the robot does (preempt, stop, drive, load, wait for a peer,
talk to the assistant), drives the `NavigationBackend`, and reports through two callables:
`publish_state(Reported)` whenever the reported state changes (never periodically) and
`publish_event(Event)` for everything the robot did. The state is published before the
matching event because the skill waits on the shadow, not on events.
"""

from __future__ import annotations

import asyncio
import inspect
import logging
from typing import TYPE_CHECKING, Any, Literal, TypeVar

import msgspec

from robot_agent.backends.port import NavigationFailed
from robot_agent.config import ExecutorSettings
from robot_agent.core.peers import PeerDeliveries
from vahr.domain.invocation import WEATHER_QUESTION
from vahr.domain.weather import WEATHER_ZONES
from vahr.protocol import (
    Deliver,
    Event,
    LastCommand,
    Navigate,
    Ping,
    Reported,
    ReportedPose,
    SequentialDelivery,
    Stop,
    WeatherDelivery,
)
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Awaitable, Callable

    from robot_agent.backends.port import NavigationBackend, Progress
    from robot_agent.clock import Clock
    from robot_agent.voice.port import Voice
    from vahr.domain import Fleet, Pose, Zone
    from vahr.protocol import Battery, Command, Result, Status

log = logging.getLogger(__name__)

# How long shutting down waits for the running task to unwind (halt the backend).
CLOSE_TIMEOUT_S = 5.0


T = TypeVar("T")

# Extra wall-clock time a voice adapter gets beyond its own listening timeout.
VOICE_GRACE_S = 5.0


async def _bounded(step: Awaitable[T], timeout_s: float, what: str) -> T:
    """Await a voice step in wall-clock time; a hung adapter becomes a SpeechError."""
    try:
        return await asyncio.wait_for(step, timeout_s)
    except TimeoutError:
        raise SpeechError(f"{what} took longer than {timeout_s:g} s") from None


class TaskFailed(Exception):
    """A task ended without doing its job; `status` is what the robot reports afterwards,
    `result` how the command ends (`rejected` or `cancelled` when the robot's navigation
    server refused or cancelled the goal)."""

    def __init__(self, reason: str, status: Status = "idle", result: Result = "failed") -> None:
        super().__init__(reason)
        self.reason = reason
        self.status = status
        self.result = result


class Executor:
    """Runs one robot's commands; see the module docstring for the contract."""

    def __init__(
        self,
        *,
        thing: str,
        fleet: Fleet,
        backend: NavigationBackend,
        clock: Clock,
        publish_state: Callable[[Reported], None],
        publish_event: Callable[[Event], None],
        voice: Voice | None = None,
        settings: ExecutorSettings | None = None,
        peers: PeerDeliveries | None = None,
    ) -> None:
        self.thing = thing
        self.fleet = fleet
        self.backend = backend
        self.clock = clock
        self.voice = voice
        self.settings = settings or ExecutorSettings()
        self.peers = peers or PeerDeliveries()
        self._publish_state = publish_state
        self._publish_event = publish_event
        zone = fleet.zone_at(backend.pose)
        self.state = Reported(
            status="idle", zone=zone.id if zone else None, pose=_pose(backend.pose)
        )
        self._task: asyncio.Task[None] | None = None
        self._current: Command | None = None
        # The zones closed now (`close_zones`): no command takes the robot into one.
        self.closed: frozenset[str] = frozenset()

    # -- inputs -------------------------------------------------------------------------

    def execute(self, command: Command) -> None:
        """Start `command` now: preempt or stop what runs, acknowledge, and run it."""
        if isinstance(command, SequentialDelivery) and command.params.after == self.thing:
            self.reject(command.id, command.action, "params.after: a robot cannot wait for itself")
            return
        closed = self._closed_on_the_way(command)
        if closed is not None:
            self.reject(command.id, command.action, f"zone {closed} is closed")
            return
        if isinstance(command, Ping):
            # Accepted and done at the same instant: one shadow update says both (the skill
            # waits for the id; on AWS each update is billed, and a fleet ping to 10,000
            # robots is 10,000 updates rather than 20,000).
            self._update(last_command=LastCommand(command.id, command.action, "done"))
            self._emit("accepted", command)
            self._emit("done", command)
            return
        previous = self._task
        if previous is not None and not previous.done():
            if self._current is not None:
                reason = f"preempted by {command.action} {command.id}"
                self._emit("cancelled", self._current, reason=reason)
            # Else the robot is leaving a closed zone on its own: a command takes over.
            previous.cancel()
        self._current = command
        accepted: dict[str, Any] = {
            "last_command": LastCommand(
                command.id, command.action, "accepted", zone=_destination(command)
            ),
            "task": command.action if command.is_motion else None,
            "destination": _destination(command),
            # Where the robot is now: the preempted task halts here and its final update,
            # like the next drive's first, then says nothing new (one update, not three).
            "pose": _pose(self.backend.pose),
        }
        if isinstance(command, Navigate):
            # What `_drive` would report a moment later: the same shadow update says it.
            accepted.update(status="navigating", zone=None)
        if isinstance(command, Stop):
            # A stop is reported once, when the robot has halted (a moment later): one
            # shadow update says accepted, stopped and done together.
            self.state = msgspec.structs.replace(self.state, **accepted)
        else:
            self._update(**accepted)
        self._emit("accepted", command)
        self._task = asyncio.get_running_loop().create_task(
            self._run(command, previous), name=f"{self.thing}:{command.action}:{command.id}"
        )

    def reject(self, command_id: str | None, action: str | None, reason: str) -> None:
        """Report a command that could not be decoded or is not allowed; nothing else changes."""
        self._report_ended("rejected", command_id, action, reason)

    def report_interrupted(self, command_id: str, action: str, reason: str) -> None:
        """Report a command an earlier run of this robot died running: it ended `failed`."""
        self._report_ended("failed", command_id, action, reason)

    def _report_ended(
        self,
        outcome: Literal["rejected", "failed"],
        command_id: str | None,
        action: str | None,
        reason: str,
    ) -> None:
        """`outcome` as the last command (named "unknown" where it could not be read) and
        as an event, for a command that never ran here."""
        last = LastCommand(command_id or "unknown", action or "unknown", outcome, reason)
        self._update(last_command=last)
        self._publish_event(
            Event(
                event=outcome,
                thing=self.thing,
                at=self.clock.now(),
                command_id=command_id,
                action=action,
                reason=reason,
            )
        )

    def peer_event(self, event: Event) -> None:
        """Take note of a peer's event (only `delivered` matters to the executor)."""
        if event.event == "delivered" and event.thing != self.thing:
            self.peers.record(event.thing, event.at)

    def report_battery(self, battery: Battery) -> None:
        """Record the battery as the backend read it; the shadow hears of it when it changes.
        Before the robot is connected it is only recorded: the whole state goes out on
        connecting (a swarm of thousands would otherwise send one update each twice)."""
        if not self.state.connected:
            self.state = msgspec.structs.replace(self.state, battery=battery)
            return
        self._update(battery=battery)

    def close_zones(self, closed: frozenset[str]) -> None:
        """The zones closed now (the fleet's retained `ZoneClosures`). The backend plans
        around their areas; a task whose way leads into one ends `failed`; a robot inside
        one leaves it."""
        closed = frozenset(zone for zone in closed if zone in self.fleet.zone_ids)
        if closed == self.closed:
            return
        self.closed = closed
        self.backend.close_zones(closed)
        if not closed:
            return
        command = self._current
        if command is not None and self.busy:
            blocked = self._closed_ahead(command)
            if blocked is None:
                return
            self._abandon(command, f"zone {blocked} was closed")
        previous = self._task
        self._task = asyncio.get_running_loop().create_task(
            self._leave_closed(previous), name=f"{self.thing}:leave"
        )

    def _closed_on_the_way(self, command: Command) -> str | None:
        """The closed zone a new command would take the robot into, if any."""
        if not self.closed or not command.is_motion:
            return None
        return self._closed_ahead(command, running=False)

    def _closed_ahead(self, command: Command, *, running: bool = True) -> str | None:
        zone = _destination(command)
        if zone is None and running and isinstance(command, WeatherDelivery):
            # Its zone is decided by the weather, then shown as the destination.
            zone = self.state.destination
        ahead = [zone] if zone else []
        # A delivery fetches its package at LOADING first, unless it has it already.
        delivers = isinstance(command, Deliver | SequentialDelivery | WeatherDelivery)
        if delivers and not self.state.cargo:
            ahead.insert(0, "LOADING")
        return next((zone for zone in ahead if zone in self.closed), None)

    def _abandon(self, command: Command, reason: str) -> None:
        """End the running task `failed` with `reason` now (its robot halts)."""
        self._current = None
        if self._task is not None:
            self._task.cancel()
        self._update(status="idle", **self._closing(command, "failed", reason))
        self._emit("failed", command, reason=reason)

    async def _leave_closed(self, previous: asyncio.Task[None] | None) -> None:
        """Drive out of every closed zone the robot is in (the backend knows where that is;
        it returns at once where the robot is not in one)."""
        if previous is not None and not previous.done():
            await _settled(previous)
        for zone_id in sorted(self.closed):
            zone = self.fleet.zone(zone_id)
            leaving = False

            def on_progress(progress: Progress) -> None:
                # Called only while the robot drives out (never when it is not inside).
                nonlocal leaving
                changes: dict[str, Any] = {"pose": _pose(progress.pose)}
                if not leaving:
                    leaving = True
                    changes.update(status="navigating", zone=None, destination=None)
                if progress.path is not None:
                    changes["path"] = [tuple(point) for point in progress.path]
                self._update(**changes)

            try:
                await self.backend.leave(zone, on_progress)
            except asyncio.CancelledError:
                await self.backend.halt()
                self._update(pose=_pose(self.backend.pose), path=None)
                raise
            except NavigationFailed as err:
                log.warning("%s: could not leave closed zone %s: %s", self.thing, zone_id, err)
            if leaving:
                here = self.fleet.zone_at(self.backend.pose)
                self._update(
                    status="idle",
                    zone=here.id if here else None,
                    pose=_pose(self.backend.pose),
                    path=None,
                )

    def set_connected(self, connected: bool) -> None:
        """Record the link state; the link publishes the full state itself on connect."""
        self.state = msgspec.structs.replace(self.state, connected=connected)

    @property
    def busy(self) -> bool:
        return self._task is not None and not self._task.done()

    async def wait_idle(self) -> None:
        """Wait until the current task (if any) has ended."""
        while self._task is not None and not self._task.done():
            await asyncio.wait({self._task})

    async def close(self) -> None:
        """Cancel the running task (it ends `cancelled`) and release the backend."""
        if self.busy and self._current is not None and self._task is not None:
            current, reason = self._current, "the agent is shutting down"
            self._emit("cancelled", current, reason=reason)
            self._current = None
            self._task.cancel()
            await asyncio.wait({self._task}, timeout=CLOSE_TIMEOUT_S)
            # The final shadow state says the task did not finish and the robot halted.
            changes: dict[str, Any] = {"status": "stopped", "task": None, "destination": None}
            last = self.state.last_command
            if last is not None and last.id == current.id:
                changes["last_command"] = LastCommand(
                    current.id, current.action, "cancelled", reason, last.zone
                )
            self._update(**changes)
        await self.backend.close()
        # A voice adapter may hold a connection or a sound device of its own.
        closer = getattr(self.voice, "close", None)
        if callable(closer):
            result = closer()
            if inspect.isawaitable(result):
                await result

    # -- tasks --------------------------------------------------------------------------

    async def _run(self, command: Command, previous: asyncio.Task[None] | None) -> None:
        if previous is not None and not previous.done():
            # The previous task halts the backend while it unwinds; wait for that.
            # `_settled`, not `await previous`: the previous task's cancellation must not
            # be raised here, and this task's own cancellation (a third command came in
            # meanwhile) must not be swallowed, or two tasks would drive at once.
            await _settled(previous)
        try:
            if isinstance(command, Stop):
                await self._stop(command)
                return
            final: Status | None = None
            if isinstance(command, Navigate):
                zone = self.fleet.zone(command.params.zone)
                await self._drive(command, zone)
                await self._arm_on_arrival(command, zone)
                # Idle and done in one shadow update, by `_close` below.
                final = "idle"
            elif isinstance(command, Deliver):
                await self._deliver(command, self.fleet.zone(command.params.zone))
            elif isinstance(command, SequentialDelivery):
                await self._sequential(command)
            elif isinstance(command, WeatherDelivery):
                await self._weather(command)
        except asyncio.CancelledError:
            # Preempted or stopped: the `cancelled` event went out when it was decided.
            await self.backend.halt()
            self._update(pose=_pose(self.backend.pose), path=None)
            raise
        except TaskFailed as failure:
            await self.backend.halt()
            self._close(command, failure.result, failure.reason, status=failure.status)
            return
        except Exception as err:  # a bug or a backend crash must not kill the agent
            log.exception("%s: task %s crashed", self.thing, command.id)
            await self.backend.halt()
            self._close(command, "failed", f"internal error: {err}", status="error")
            return
        self._close(command, "done", None, status=final or self.state.status)

    async def _stop(self, command: Stop) -> None:
        await self.backend.halt()
        self._update(
            status="stopped",
            task=None,
            destination=None,
            path=None,
            pose=_pose(self.backend.pose),
            last_command=LastCommand(command.id, command.action, "done"),
        )
        self._emit("stopped", command, pose=self.backend.pose)
        self._emit("done", command)

    async def _drive(self, command: Command, zone: Zone) -> None:
        self._update(
            status="navigating", zone=None, destination=zone.id, pose=_pose(self.backend.pose)
        )
        if self.backend.pose.distance_to(zone.pose) > zone.radius:
            await self._navigate_watched(command, zone)
        self._update(status="navigating", zone=zone.id, pose=_pose(self.backend.pose), path=None)
        self._emit("arrived", command, zone=zone.id, pose=self.backend.pose)

    async def _navigate_watched(self, command: Command, zone: Zone) -> None:
        """Drive with stuck detection: no progress for `stuck_after_s` ends the task.

        "No progress" is judged on the backend's own time when its reports carry it
        (`Progress.at`, the simulator's): a robot is stuck when its reports stayed still
        from the first still one for `stuck_after_s`. A process too busy to step the
        simulator delays the motion and its reports alike, and the next step covers the
        time lost, so a busy process never makes a robot look stuck. A backend without
        that time (ROS) is watched on the clock instead.
        """
        loop = asyncio.get_running_loop()
        last_advance = self.clock.monotonic()
        last_progress: Progress | None = None
        # The drive's start counts as a report: the shadow said `navigating` from here.
        last_report, last_fraction = last_advance, 0.0
        interval, step = self.settings.progress_interval_s, self.settings.progress_step
        stuck_after = self.settings.stuck_after_s
        # Set when the backend's timed reports show no progress for `stuck_after`.
        stalled = False
        timed = False
        # The time of the first of the latest run of timed reports that did not advance.
        # Not the last advance: the time between that and the first still report may be
        # time nothing was simulated in (the process was busy), not time standing still.
        still_since: float | None = None
        active = True

        def on_progress(progress: Progress) -> None:
            nonlocal last_advance, last_progress, last_report, last_fraction, timed, still_since
            nonlocal stalled
            if not active or self._current is not command:
                # Feedback a backend queued before the goal ended (ROS threads) comes late;
                # after `cancelled` or `arrived` the task has nothing more to say.
                return
            if progress.at is None:
                now = self.clock.monotonic()
            else:
                now, timed = progress.at, True
            if last_progress is None or _advanced(last_progress, progress):
                last_advance, still_since = now, None
            elif timed:
                if still_since is None:
                    still_since = now
                elif now - still_since > stuck_after and not stalled:
                    stalled = True
                    wake_up()
            last_progress = progress
            if progress.path is not None:
                # A new plan (at the start, or after a zone closed): the shadow says it.
                self._update(path=[tuple(point) for point in progress.path])
            fraction = min(max(progress.fraction, 0.0), 1.0)
            # Both bounds must hold (see ExecutorSettings); `step` is compared with a little
            # slack so that float steps of exactly a quarter still count as a quarter. The
            # start and the end of the way are never reported: nothing is done yet, or
            # `arrived`, with the pose, follows at once.
            # Compared as reported (three decimals): 0.9996 would be reported as 1.0.
            if (
                0 < round(fraction, 3) < 1
                and now - last_report >= interval
                and fraction - last_fraction >= step - 1e-9
            ):
                last_report, last_fraction = now, fraction
                if self.backend.observed_pose:
                    # Where a real robot is comes from the robot: the shadow follows it at
                    # the rate of the progress reports (the state before its event).
                    self._update(pose=_pose(progress.pose))
                self._emit(
                    "progress",
                    command,
                    zone=zone.id,
                    progress=round(fraction, 3),
                    pose=progress.pose,
                    eta_s=_rounded(progress.eta_s),
                    distance_remaining_m=_rounded(progress.distance_remaining_m),
                )

        # One future wakes this task: the drive ending, the backend stalling, or (without
        # timed reports) the watchdog's timer. Cheaper than asyncio.wait, which a swarm of
        # 10,000 robots would call for every robot at every command.
        wake: asyncio.Future[None] = loop.create_future()

        def wake_up(*_: object) -> None:
            if not wake.done():
                wake.set_result(None)

        drive = loop.create_task(self.backend.go_to(zone, on_progress))
        drive.add_done_callback(wake_up)
        check_every = _wall(self.clock, max(stuck_after / 4, 0.05))
        try:
            while not drive.done():
                if wake.done():
                    wake = loop.create_future()
                # Once the backend's reports carry its time, it says itself when the robot
                # stalls: no timer per robot.
                timer = None if timed else loop.call_later(check_every, wake_up)
                try:
                    await wake
                finally:
                    if timer is not None:
                        timer.cancel()
                if drive.done():
                    break
                if not stalled:
                    if self.clock.monotonic() - last_advance <= stuck_after:
                        continue
                    # A starved process wakes this watchdog and the backend at the same
                    # moment; let the backend report first so starvation is not "stuck".
                    for _ in range(3):
                        await asyncio.sleep(0)
                    if timed or self.clock.monotonic() - last_advance <= stuck_after:
                        continue
                drive.cancel()
                await _settled(drive)
                reason = f"no progress towards {zone.id} for {stuck_after:g} s"
                self._update(status="stuck", pose=_pose(self.backend.pose))
                self._emit("stuck", command, zone=zone.id, reason=reason, pose=self.backend.pose)
                raise TaskFailed(f"stuck: {reason}", status="stuck")
            try:
                drive.result()
            except NavigationFailed as err:
                raise TaskFailed(str(err), status=err.status, result=err.result) from err
        finally:
            active = False
            if not drive.done():
                drive.cancel()
                await _settled(drive)

    async def _deliver(self, command: Command, zone: Zone) -> None:
        loading = self.fleet.zone("LOADING")
        # A weather delivery learns its zone only now; a zone closed is not driven into.
        for place in (zone,) if self.state.cargo else (loading, zone):
            if place.id in self.closed:
                raise TaskFailed(f"zone {place.id} is closed")
        if not self.state.cargo:
            await self._drive(command, loading)
            await self._load(command, loading)
        self._update(destination=zone.id)
        await self._drive(command, zone)
        # A delivery ends unloaded wherever it was sent, whatever arm the zone has.
        await self._unload(command, zone)

    async def _load(self, command: Command, zone: Zone) -> None:
        self._update(status="loading")
        await self.backend.operate_arm(zone)
        self._update(cargo=True)
        self._emit("loaded", command, zone=zone.id)

    async def _unload(self, command: Command, zone: Zone) -> None:
        self._update(status="unloading")
        await self.backend.operate_arm(zone)
        # Unloading is the last step of every task that unloads: the same shadow update
        # closes the task, before `delivered` and `done` are said.
        self._update(status="idle", cargo=False, **self._closing(command, "done", None))
        self._emit("delivered", command, zone=zone.id, pose=self.backend.pose)

    async def _arm_on_arrival(self, command: Command, zone: Zone) -> None:
        """The zone's arm acts on its own when a robot arrives, as on the paper's floor:
        the loader loads an empty robot, an unloader unloads a loaded one; otherwise the
        arm leaves the robot alone. A plain `navigate` is therefore enough to load at
        LOADING and to deliver at a zone (the keyboard-and-mouse procedure relies on it)."""
        if zone.arm == "loader" and not self.state.cargo:
            await self._load(command, zone)
        elif zone.arm == "unloader" and self.state.cargo:
            await self._unload(command, zone)

    async def _sequential(self, command: SequentialDelivery) -> None:
        after = command.params.after
        zone = self.fleet.zone(command.params.zone)
        if after is not None and after != self.thing:
            skew = self.settings.peer_clock_skew_s
            if self.peers.delivered_since(after, command.issued_at, skew) is None:
                timeout = self.settings.sequential_timeout_s
                self._update(status="waiting")
                self._emit("waiting", command, reason=f"waiting for {after} to deliver")
                next_delivery = self.peers.next_delivery(after)
                waited = await _wait_for(self.clock, next_delivery, timeout)
                if not waited:
                    raise TaskFailed(f"{after} did not deliver within {timeout:g} s")
        await self._deliver(command, zone)

    async def _weather(self, command: WeatherDelivery) -> None:
        if self.voice is None:
            raise TaskFailed("voice not configured")
        self._update(status="waiting", destination=None)
        intent = None
        heard_text = ""
        try:
            for _attempt in range(2):
                await self._say(WEATHER_QUESTION)
                self._emit("said", command, text=WEATHER_QUESTION)
                heard = await _bounded(
                    self.voice.listen(self.settings.listen_timeout_s),
                    self.settings.listen_timeout_s + VOICE_GRACE_S,
                    "listening",
                )
                heard_text = heard.text
                self._emit("heard", command, text=heard.text)
                self._emit("interpreted", command, intent=heard.intent, confidence=heard.confidence)
                if heard.intent in WEATHER_ZONES:
                    intent = heard.intent
                    break
            if intent is None:
                raise TaskFailed(
                    f"did not understand the weather answer twice (last heard: {heard_text!r})"
                )
            zone_id = WEATHER_ZONES[intent]
            acknowledgment = f"Thank you. It is {intent}, so I am delivering to zone {zone_id}."
            await self._say(acknowledgment)
            self._emit("said", command, text=acknowledgment)
        except SpeechError as err:
            raise TaskFailed(f"voice failed: {err}") from err
        await self._deliver(command, self.fleet.zone(zone_id))

    async def _say(self, text: str) -> None:
        assert self.voice is not None
        await _bounded(self.voice.say(text), self.settings.speak_timeout_s, "speaking")

    # -- reporting ----------------------------------------------------------------------

    def _close(
        self, command: Command, result: Result, reason: str | None, *, status: Status
    ) -> None:
        # A failure names the zone it was for: its reason names it by id.
        zone = None if result == "done" else self._zone_of(command)
        self._update(status=status, **self._closing(command, result, reason))
        self._emit(result, command, reason=reason, zone=zone)
        if self._current is command:
            self._current = None

    def _closing(self, command: Command, result: Result, reason: str | None) -> dict[str, Any]:
        """The state changes that end `command` with `result`."""
        changes: dict[str, Any] = {"task": None, "destination": None, "path": None}
        changes["pose"] = _pose(self.backend.pose)
        # A ping may have become the last command meanwhile; only our own entry is closed.
        last = self.state.last_command
        if last is None or last.id == command.id or last.action == "ping":
            changes["last_command"] = LastCommand(
                command.id, command.action, result, reason, self._zone_of(command)
            )
        return changes

    def _zone_of(self, command: Command) -> str | None:
        """The zone `command` is for: its own, or where it turned out to go (a weather
        delivery's zone, known once the weather is)."""
        return _destination(command) or self.state.destination

    def _update(self, **changes: Any) -> None:
        new = msgspec.structs.replace(self.state, **changes)
        if new != self.state:
            self.state = new
            self._publish_state(new)

    def _emit(
        self, kind: str, command: Command, *, pose: Pose | None = None, **fields: Any
    ) -> None:
        event = Event(
            event=kind,  # type: ignore[arg-type]
            thing=self.thing,
            at=self.clock.now(),
            command_id=command.id,
            action=command.action,
            pose=ReportedPose(pose.x, pose.y, pose.theta) if pose is not None else None,
            **fields,
        )
        self._publish_event(event)


def _destination(command: Command) -> str | None:
    params = command.params
    zone = getattr(params, "zone", None)
    return zone if isinstance(zone, str) else None


def _rounded(value: float | None) -> float | None:
    return None if value is None else round(value, 2)


def _pose(pose: Pose) -> ReportedPose:
    return ReportedPose(round(pose.x, 3), round(pose.y, 3), round(pose.theta, 3))


def _advanced(before: Progress, after: Progress) -> bool:
    moved = before.pose.distance_to(after.pose) > 0.01
    turned = abs(before.pose.theta - after.pose.theta) > 0.01
    return moved or turned or after.fraction > before.fraction + 1e-3


async def _settled(task: asyncio.Future[Any]) -> None:
    """Wait until `task` is done, whatever its outcome, without raising it; this task's own
    cancellation is raised as usual. asyncio.wait({task}) does the same at several times
    the cost."""
    if task.done():
        return
    settled = asyncio.get_running_loop().create_future()

    def on_done(_: asyncio.Future[Any]) -> None:
        if not settled.done():
            settled.set_result(None)

    task.add_done_callback(on_done)
    try:
        await settled
    finally:
        task.remove_done_callback(on_done)


def _wall(clock: Clock, seconds: float) -> float:
    to_wall = getattr(clock, "to_wall_seconds", None)
    return float(to_wall(seconds)) if callable(to_wall) else seconds


async def _wait_for(clock: Clock, future: asyncio.Future[Any], timeout_s: float) -> bool:
    """Wait for `future` up to `timeout_s` of simulated time; False on timeout."""
    sleeper = asyncio.ensure_future(clock.sleep(timeout_s))
    try:
        done, _ = await asyncio.wait({future, sleeper}, return_when=asyncio.FIRST_COMPLETED)
        return future in done
    finally:
        sleeper.cancel()
        if not future.done():
            future.cancel()
