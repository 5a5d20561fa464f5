"""Who performs the tasks: the simulated participant (for `vahr demo`, rehearsals and tests).

The simulated participant drives the real system: with the voice method it speaks to the
assistant (`Assistant`), with the keyboard-and-mouse method it clicks in the console, which
publishes the same commands directly (source "console"). Its timing follows
`vahr.experiment.timing`; it logs the start and end of each utterance or click sequence,
and solves puzzle pieces while the robots work. Everything it logs is marked simulated in
the session header.

Durations of the timing model are experiment seconds; they are slept for
`seconds / speed_factor` of wall time, so a rehearsal can run as fast as the simulated
robots (whose speed factor must then be the same).
"""

from __future__ import annotations

import itertools
import random
import time
from typing import TYPE_CHECKING, Any

from vahr.experiment.eventlog import Kind
from vahr.protocol import encode, new_command, topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.experiment.assistant import Assistant
    from vahr.experiment.eventlog import EventLog
    from vahr.experiment.tasks import Plan
    from vahr.experiment.timing import TimingModel
    from vahr.protocol import Fleet

Click = tuple[str, str, dict[str, Any]]  # robot, action, params


class Console:
    """The keyboard-and-mouse method's console: one button per robot, action and zone."""

    def __init__(self, publish: Callable[[str, bytes], None]) -> None:
        self._publish = publish

    def send(self, thing: str, action: str, params: dict[str, Any]) -> str:
        """Publish a command to one robot, as the skill would; return its id."""
        command = new_command(action, params, source="console")
        self._publish(topics.robot_cmd(thing), encode(command))
        return command.id


def voice_script(task: str, plan: Plan, fleet: Fleet) -> list[str]:
    """What a participant says to the assistant for each task (the skill's sample phrasing)."""
    first, second = fleet.robot_things[0], fleet.robot_things[1]
    name = fleet.spoken_name
    if task == "I":
        return [
            f"tell {name(thing)} to deliver a package to zone {zone}"
            for thing, zone in plan.goal("I").zones.items()
        ]
    if task == "II":
        return [f"tell {name(plan.weather_robot)} to do the weather delivery"]
    zone = plan.goal("III").zones[first]
    return [
        f"have {name(first)} deliver to zone {zone} and then {name(second)} deliver to zone {zone}"
    ]


def keyboard_script(task: str, plan: Plan) -> list[Click]:
    """The commands a participant sends from the console for each task.

    Task II: the console shows the weather, so the participant picks the zone themselves.
    """
    goal = plan.goal(task)
    if task in ("I", "II"):
        return [(thing, "deliver", {"zone": zone}) for thing, zone in goal.zones.items()]
    first, *rest = goal.order
    clicks: list[Click] = [(first, "deliver", {"zone": goal.zones[first]})]
    previous = first
    for thing in rest:
        clicks.append(
            (thing, "sequential_delivery", {"zone": goal.zones[thing], "after": previous})
        )
        previous = thing
    return clicks


def click_label(click: Click) -> str:
    """How a click sequence is named in the log: `placebot1 deliver zone=B`."""
    thing, action, params = click
    return " ".join([thing, action, *(f"{k}={v}" for k, v in params.items())])


class SimulatedParticipant:
    """Performs each task with one method, following the timing model."""

    simulated = True

    def __init__(
        self,
        *,
        method: str,
        fleet: Fleet,
        plan: Plan,
        log: EventLog,
        timing: TimingModel,
        seed: int,
        speed_factor: float = 1.0,
        assistant: Assistant | None = None,
        console: Console | None = None,
    ) -> None:
        if method == "vahr" and assistant is None:
            raise ValueError("the voice method needs an assistant")
        if method == "keyboard" and console is None:
            raise ValueError("the keyboard method needs a console")
        self.method = method
        self.fleet = fleet
        self.plan = plan
        self.log = log
        self.timing = timing
        self.rng = random.Random(seed ^ 0x5EED)
        self.speed_factor = speed_factor
        self.assistant = assistant
        self.console = console
        self._ids = itertools.count(1)

    def _sleep(self, experiment_s: float) -> None:
        time.sleep(experiment_s / self.speed_factor)

    def _new_id(self, task: str) -> str:
        return f"{task}-{next(self._ids)}"

    def perform(self, task: str, done: list[str] | None = None) -> None:
        """Issue the task's commands, one interaction at a time, skipping those in `done`
        (completed before the session was interrupted)."""
        remaining = list(done or [])
        if self.method == "vahr":
            for utterance in voice_script(task, self.plan, self.fleet):
                if utterance in remaining:
                    remaining.remove(utterance)
                    continue
                self._speak(task, utterance)
        else:
            for click in keyboard_script(task, self.plan):
                if click_label(click) in remaining:
                    remaining.remove(click_label(click))
                    continue
                self._click(task, click)

    def _speak(self, task: str, utterance: str) -> None:
        assert self.assistant is not None
        ident = self._new_id(task)
        self.log.append(
            Kind.INTERACTION_STARTED,
            {"id": ident, "channel": "voice", "text": utterance},
            task=task,
        )
        self._sleep(self.timing.speaking_s(self.rng, utterance))
        reply = self.assistant.ask(utterance)
        self._sleep(self.timing.listening_s(self.rng, reply.speech))
        body: dict[str, Any] = {
            "id": ident,
            "channel": "voice",
            "text": utterance,
            "speech": reply.speech,
            "intent": reply.intent,
            "commands": reply.commands,
        }
        if reply.error:
            body["error"] = reply.error
        self.log.append(Kind.INTERACTION_ENDED, body, task=task)

    def _click(self, task: str, click: Click) -> None:
        assert self.console is not None
        thing, action, params = click
        ident = self._new_id(task)
        label = click_label(click)
        self.log.append(
            Kind.INTERACTION_STARTED,
            {"id": ident, "channel": "click", "text": label},
            task=task,
        )
        self._sleep(self.timing.first_click_s(self.rng))  # the robot's button
        for _ in range(3):  # action, zone, send
            self._sleep(self.timing.next_click_s(self.rng))
        body: dict[str, Any] = {"id": ident, "channel": "click", "text": label, "clicks": 4}
        try:
            body["commands"] = [self.console.send(thing, action, params)]
        except Exception as err:  # noqa: BLE001 - any publish failure is the interaction's outcome
            body["commands"], body["error"] = [], str(err)
        self.log.append(Kind.INTERACTION_ENDED, body, task=task)

    def wait(self, decided: Callable[[], bool], timeout_s: float) -> bool:
        """Solve puzzle pieces until the task is decided or `timeout_s` (experiment seconds)
        pass; True if it was decided."""
        elapsed = 0.0
        next_piece = self.timing.puzzle_piece_s(self.rng)
        # Look at the robots every 0.25 experiment seconds, but not more often than every
        # 20 ms of wall time: a fast rehearsal must not spin on the shared CPU.
        step = max(0.25, 0.02 * self.speed_factor)
        while elapsed < timeout_s:
            if decided():
                return True
            self._sleep(step)
            elapsed += step
            next_piece -= step
            if next_piece <= 0:
                self.log.append(
                    Kind.OBSERVER,
                    {"what": "puzzle_piece", "count": 1, "by": "simulated participant"},
                )
                next_piece = self.timing.puzzle_piece_s(self.rng)
        return decided()
