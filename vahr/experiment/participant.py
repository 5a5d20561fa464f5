"""The simulated participant: performs the paper's procedures through the real system.

With the voice method it speaks to the assistant (`Assistant`); with the keyboard-and-mouse
method it clicks on the station's map, which publishes navigation orders (`Console`, source
"console"). What it does in each task is `vahr.experiment.procedures`; how long each part
takes is `vahr.experiment.timing`. It logs the start and end of every utterance, order and
glance, and each puzzle part it solves; its sessions are marked simulated.

How it spends a task:

1. it takes every step whose observations it has made, one after another (a block: the
   hand goes to the mouse once, and back to the puzzle after the block's last click);
2. otherwise it works on the puzzle; each time a part is done, if some step waits for
   something to be seen (a robot loaded, a robot delivered), it glances at the screen and
   sees what has happened by then (or, with `Person.monitoring == "watch"`, it keeps its
   eyes on the screen until it sees it; with `"announce"` it never looks, and learns that
   a robot was loaded or delivered when the assistant announces its finished task, as
   `vahr.announce` decides with `done` on). What is heard (a robot's exchange with the
   assistant ending) is noticed at once. Looking and listening to an announcement count
   as interaction, as the paper counts watching;
3. once every step is taken it keeps solving the puzzle until the task is decided.

Clock: durations are study seconds, slept for `seconds / speed_factor` of wall time, so a
rehearsal runs as fast as the simulated robots (whose speed factor must be the same). The
assistant's real response time is counted once, in real seconds, as the KLM's R(t): the
time the call took beyond its share at the speed factor is taken out of the listening that
follows, and any remainder is logged as `overrun_s`.
"""

from __future__ import annotations

import itertools
import random
import time
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.announce import AnnouncePolicy, settings_from, signals_from_event
from vahr.announce.speech import Names
from vahr.domain import Pose
from vahr.errors import VahrError
from vahr.experiment import timing
from vahr.experiment.eventlog import Kind
from vahr.experiment.procedures import Observation, check_action, heard_weather, procedure_for
from vahr.protocol import Event, ProtocolError, encode, new_command, topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain import Fleet
    from vahr.experiment.eventlog import EventLog, LogEntry
    from vahr.experiment.procedures import Procedure, Step
    from vahr.experiment.tasks import Plan
    from vahr.plumbing.client import Assistant
    from vahr.protocol.announcements import Announcement

# A question the assistant does not answer with a weather is asked again, up to this often.
QUESTION_ATTEMPTS = 3
# How often (study seconds) the runner's "is the task decided" is looked at while puzzling.
POLL_S = 0.25
# Never poll more often than this in wall time: a fast rehearsal must not spin on 2 cores.
POLL_WALL_S = 0.02
GLANCE_TEXT = "glance at the screen"
HEAR_TEXT = "hear an announcement"
# The announcer's settings for a participant who monitors by announcements. They act on
# every finished task (it is how they learn a robot was loaded or delivered), so `done` is
# on and the rate limit must never hold one back: a task of the paper's procedures brings
# at most four (two robots, two legs each: `procedures`), a minute can hold the end of one
# task and the start of the next, so eight routine announcements a minute, and one more
# kept for urgent news (the default reserve), never hold a completion back. Priorities are
# the announcer's own (stuck and offline first, done last).
ANNOUNCE_SETTINGS = {
    "kinds": ["stuck", "failed", "offline", "done"],
    "max_per_window": 9,
    "window_s": 60.0,
    "reserve_for_urgent": 1,
}
WATCH_TEXT = "watch the screen"


class Console:
    """The keyboard-and-mouse panel's send path: publishes orders as the skill would.

    Every order is checked against the paper's procedure for the method and task first, so
    a keyboard session can never send a compound command.
    """

    def __init__(self, publish: Callable[[str, bytes], None], method: str = "keyboard") -> None:
        self._publish = publish
        self.method = method

    def send(self, thing: str, action: str, params: dict[str, Any], *, task: str | None) -> str:
        """Publish a command to one robot, as the skill would; return its id."""
        check_action(self.method, task, action)
        command = new_command(action, params, source="console")
        self._publish(topics.robot_cmd(thing), encode(command))
        return command.id


class SimulatedParticipant:
    """Performs each task with one method, following the paper's procedure."""

    simulated = True

    def __init__(
        self,
        *,
        method: str,
        fleet: Fleet,
        plan: Plan,
        log: EventLog,
        person: timing.Person,
        seed: int,
        speed_factor: float = 1.0,
        assistant: Assistant | None = None,
        console: Console | None = None,
    ) -> None:
        if method == "vahr" and assistant is None:
            raise ValueError("the voice method needs an assistant")
        if method == "keyboard" and (assistant is None or console is None):
            raise ValueError("the keyboard method needs the console and the assistant")
        self.method = method
        self.fleet = fleet
        self.plan = plan
        self.log = log
        self.person = person
        self.rng = random.Random(seed ^ 0x5EED)
        self.speed_factor = speed_factor
        self.assistant = assistant
        self.console = console
        self._ids = itertools.count(1)
        self._task: str | None = None
        self._procedure: Procedure | None = None
        self._start_seq = 0
        self._done: set[int] = set()
        self._asked: dict[int, int] = {}
        self._observed: set[Observation] = set()
        self._visible: set[Observation] = set()  # on the screen, seen at the next glance
        self._talked: set[str] = set()  # robots that have heard the assistant's answer
        self._poses: dict[str, Pose] = {}
        self._read_seq = 0
        self._weather: dict[str, str] = {}
        self._cursor = timing.screen_point(Pose(5.0, 4.0, 0.0))  # the map's middle
        self._block: str | None = None  # "voice"/"click" while a block of steps goes on
        self._last_listen_s = 0.0
        # `announce` monitoring: the announcer's policy on the study's clock.
        self._began = (time.monotonic(), datetime.now(UTC))
        self._announcer = (
            AnnouncePolicy(settings_from(ANNOUNCE_SETTINGS), Names.of(fleet), self._study_now)
            if person.monitoring == "announce"
            else None
        )
        self._heard: list[Announcement] = []

    # -- the clock ------------------------------------------------------------------------

    def _study_now(self) -> datetime:
        wall, at = self._began
        return at + timedelta(seconds=(time.monotonic() - wall) * self.speed_factor)

    def _sleep(self, study_s: float) -> None:
        if study_s > 0:
            time.sleep(study_s / self.speed_factor)

    # -- the runner's interface -----------------------------------------------------------

    def perform(self, task: str, done: list[str] | None = None) -> None:
        """Start `task`: take the steps that need nothing observed. `done` names the
        interactions (by text) already completed in it before the session was interrupted."""
        self._task = task
        self._procedure = procedure_for(self.method, task, self.plan, self.fleet)
        starts = [e for e in self.log.entries(Kind.TASK_STARTED) if e.data.get("task") == task]
        self._start_seq = starts[-1].seq if starts else 0
        self._done, self._asked, self._weather = set(), {}, {}
        remaining = list(done or [])
        for step in self._procedure.steps:
            if step.label in remaining:
                remaining.remove(step.label)
                self._done.add(step.index)
        self._observed, self._visible, self._talked = set(), set(), set()
        self._read_seq = min(self._read_seq, self._start_seq)
        self._recall_answers()
        self._look(sight=True)  # on resume the screen shows what happened meanwhile
        self._block = None
        self._take_ready_steps()

    def wait(self, decided: Callable[[], bool], timeout_s: float) -> bool:
        """Puzzle, glance and take the remaining steps until the task is decided or
        `timeout_s` study seconds pass; True if it was decided."""
        deadline = time.monotonic() + timeout_s / self.speed_factor
        poll = max(POLL_S, POLL_WALL_S * self.speed_factor)
        part_left = timing.puzzle_part_s(self.rng)
        while time.monotonic() < deadline:
            if decided():
                return True
            self._look(sight=False)
            if self._take_ready_steps():
                continue
            self._block = None
            if self._heard:
                self._hear(self._heard.pop(0))
                continue
            if self.person.monitoring == "watch" and self._must_watch():
                self._watch(decided, deadline, poll)
                continue
            work = min(part_left, poll)
            self._sleep(work)
            part_left -= work
            if part_left <= 1e-9:
                self.log.append(
                    Kind.OBSERVER,
                    {"what": "puzzle_piece", "count": 1, "by": "simulated participant"},
                    task=self._task,
                )
                part_left = timing.puzzle_part_s(self.rng)
                if self._must_watch() and self._announcer is None:
                    self._glance()
        return decided()

    # -- what the participant knows -------------------------------------------------------

    def _task_entries(self) -> list[LogEntry]:
        return self.log.entries(after=self._start_seq)

    def _read_log(self) -> None:
        """Follow the log: what is on the screen, who has finished talking, where robots are."""
        fresh = self.log.entries(Kind.ROBOT_EVENT, after=self._read_seq)
        if not fresh:
            return
        self._read_seq = fresh[-1].seq
        for entry in fresh:
            thing, event = str(entry.data.get("thing")), entry.data.get("event")
            reported = entry.data.get("pose")
            if isinstance(reported, dict):
                self._poses[thing] = Pose(float(reported["x"]), float(reported["y"]), 0.0)
            if entry.seq <= self._start_seq:
                continue
            self._announce(entry.data)
            if event in ("loaded", "delivered"):
                self._visible.add(Observation(thing, event))
            elif event == "interpreted":
                self._talked.add(thing)
            elif event == "said" and thing in self._talked:
                self._observed.add(Observation(thing, "spoke"))  # its acknowledgment, heard

    def _look(self, *, sight: bool) -> list[str]:
        """Update what is known: what is heard always, what is on the screen when `sight`
        (a glance). Returns what was newly seen."""
        self._read_log()
        if self._announcer is not None:
            # What the rate limit held back is told as soon as it may, not at the next event.
            self._heard += self._announcer.tick()
        if not sight:
            return []
        noticed = sorted(o.describe() for o in self._visible - self._observed)
        self._observed |= self._visible
        return noticed

    def _recall_answers(self) -> None:
        """On resume: the weather answers already heard in this task."""
        for entry in self._task_entries():
            if entry.kind == Kind.INTERACTION_ENDED and entry.data.get("asks"):
                weather = heard_weather(str(entry.data.get("speech", "")))
                if weather is not None:
                    self._answered(str(entry.data["asks"]), weather)

    def _answered(self, thing: str, weather: str) -> None:
        self._weather[thing] = weather
        self._observed.add(Observation(thing, "answered"))

    def _must_watch(self) -> bool:
        """Does a step still wait for something only a look at the screen can tell?"""
        assert self._procedure is not None
        return any(
            need.by_sight and need not in self._observed
            for step in self._procedure.steps
            if step.index not in self._done
            for need in step.requires
        )

    def _robot_point(self, thing: str) -> tuple[float, float]:
        """Where the robot's marker is on the map: its last reported pose."""
        self._read_log()
        return timing.screen_point(self._poses.get(thing, self.fleet.robot(thing).start))

    # -- acting -----------------------------------------------------------------------------

    def _take_ready_steps(self) -> bool:
        """Take the ready steps one after another; True if any was taken."""
        assert self._procedure is not None
        took = False
        while True:
            ready = self._procedure.ready(self._observed, self._done)
            if not ready:
                return took
            step = ready[0]
            more_clicks = any(s.channel == "click" for s in ready[1:])
            if step.channel == "click":
                self._click(step, hand_back=not more_clicks)
            else:
                self._speak(step)
            took = True
            self._look(sight=False)

    def _interaction(self, channel: str, text: str, **extra: Any) -> str:
        ident = f"{self._task}-{next(self._ids)}"
        self.log.append(
            Kind.INTERACTION_STARTED,
            {"id": ident, "channel": channel, "text": text, **extra},
            task=self._task,
        )
        return ident

    def _end(self, ident: str, channel: str, text: str, **body: Any) -> None:
        self.log.append(
            Kind.INTERACTION_ENDED,
            {"id": ident, "channel": channel, "text": text, **body},
            task=self._task,
        )

    def _glance(self) -> None:
        ident = self._interaction("watch", GLANCE_TEXT, counts=False)
        self._sleep(self.person.glance_s())
        seen = self._look(sight=True)
        self._end(ident, "watch", GLANCE_TEXT, counts=False, commands=[], seen=seen)

    def _announce(self, data: dict[str, Any]) -> None:
        """What the assistant announces about this robot event (`announce` monitoring)."""
        if self._announcer is None:
            return
        try:
            event = msgspec.convert(data, Event, strict=False)
        except (msgspec.ValidationError, ProtocolError):
            return
        self._heard += self._announcer.observe(signals_from_event(event))

    def _hear(self, announcement: Announcement) -> None:
        """Listen to an announcement; a finished task tells what its robot's marker shows."""
        ident = self._interaction("voice", HEAR_TEXT, counts=False)
        self._sleep(self.person.hearing_s(announcement.speech))
        learnt = {o for o in self._visible if o.thing == announcement.thing}
        self._observed |= learnt
        self._end(
            ident, "voice", HEAR_TEXT, counts=False, commands=[],
            speech=announcement.speech, seen=sorted(o.describe() for o in learnt),
        )  # fmt: skip

    def _watch(self, decided: Callable[[], bool], deadline: float, poll: float) -> None:
        """Keep the eyes on the screen until something awaited shows (the `watch` variant)."""
        ident = self._interaction("watch", WATCH_TEXT, counts=False)
        seen: list[str] = []
        while not seen and not decided() and time.monotonic() < deadline:
            self._sleep(poll)
            seen = self._look(sight=True)
        self._end(ident, "watch", WATCH_TEXT, counts=False, commands=[], seen=seen)

    def _speak(self, step: Step) -> None:
        assert self.assistant is not None and step.utterance is not None
        text = step.utterance
        extra: dict[str, Any] = {"asks": step.thing} if step.is_question else {}
        ident = self._interaction("voice", text, **extra)
        if self._block == "voice":
            # Prepared while the previous reply played (Levinson & Torreira 2015).
            prepare = max(self.person.turn_gap_s(), self.person.mental_s() - self._last_listen_s)
        else:
            prepare = self.person.mental_s()
        self._sleep(prepare + self.person.speaking_s(text))
        started = time.monotonic()
        try:
            turn, error = self.assistant.ask(text), None
        except VahrError as err:
            # A failed exchange is logged as one and the task goes on, as a person would.
            turn, error = {}, str(err)
        latency = time.monotonic() - started
        speech = str(turn.get("speech") or "")
        listen = timing.listening_s(speech)
        # The call took `latency` of wall time; at the speed factor only latency / F of it
        # belongs to the rehearsal's clock. Take the rest out of the listening.
        excess = latency - latency / self.speed_factor
        listen_wall = listen / self.speed_factor - excess
        overrun = max(0.0, -listen_wall) * self.speed_factor
        if listen_wall > 0:
            time.sleep(listen_wall)
        self._block, self._last_listen_s = "voice", listen
        commands = turn.get("commands")
        body: dict[str, Any] = {
            "speech": speech,
            "intent": str(turn["intent"]) if turn.get("intent") else None,
            "commands": [str(c) for c in commands] if isinstance(commands, list) else [],
            "latency_ms": round(latency * 1000, 1),
            "overrun_s": round(overrun, 3),
            **extra,
        }
        if error:
            body["error"] = error
        if step.is_question:
            weather = heard_weather(speech)
            if weather is not None:
                self._answered(step.thing, weather)
            body["commands"] = []
        self._end(ident, "voice", text, **body)
        attempts = self._asked[step.index] = self._asked.get(step.index, 0) + 1
        if not step.is_question or step.thing in self._weather or attempts >= QUESTION_ATTEMPTS:
            self._done.add(step.index)

    def _click(self, step: Step, *, hand_back: bool) -> None:
        assert self.console is not None and step.action is not None
        resolved = step.resolved(self._weather.get(step.thing))
        assert resolved.zone is not None
        zone = self.fleet.zone(resolved.zone)
        ident = self._interaction("click", resolved.label)
        person = self.person
        robot = self._robot_point(step.thing)
        target = timing.screen_point(zone.pose)
        # M, then (first in a block) H, then point at the robot and click, point at the zone
        # and click: the order is sent on the second click.
        seconds = person.mental_s() + (person.homing_s() if self._block != "click" else 0.0)
        seconds += person.point_s(self._cursor, robot, timing.ROBOT_MARKER.value)
        seconds += person.click_s()
        seconds += person.point_s(robot, target, 2 * zone.radius) + person.click_s()
        self._sleep(seconds)
        self._cursor, self._block = target, "click"
        body: dict[str, Any] = {"clicks": 2}
        try:
            body["commands"] = [
                self.console.send(step.thing, step.action, {"zone": resolved.zone}, task=self._task)
            ]
        except Exception as err:  # noqa: BLE001 - any publish failure is the order's outcome
            body["commands"], body["error"] = [], str(err)
        if hand_back:
            self._sleep(person.homing_s())  # back to the puzzle
            self._block = None
        self._end(ident, "click", resolved.label, **body)
        self._done.add(step.index)
