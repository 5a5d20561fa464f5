"""The paper's procedures: what a participant does in each task with each method, as data.

One home for the rules that the simulated participant follows, that the judge checks, that
the observer's console enforces, and that the station's keyboard-and-mouse panel will offer
(see docs/experiment.md, "Procedures"). The facts are the paper's
(docs/experiment.md):

- Task I. Voice: per robot, "navigate to the loading zone"; once it is loaded, "navigate
  to" its zone. Keyboard and mouse: the same two navigation orders per robot, clicked on the
  station's map.
- Task II. Voice: per robot, the weather-navigation intent (the robot asks the assistant
  itself); the second once the first robot's spoken exchange has ended. Keyboard and mouse:
  ask the assistant for the weather once per robot, then per robot navigate to LOADING
  and, once it is loaded, to the zone the weather calls for.
- Task III. Voice: one sequential-delivery intent (placebot1, then placebot2, to D).
  Keyboard and mouse: placebot1 to LOADING, once loaded to D; once placebot1 has
  delivered, placebot2 to LOADING and, once loaded, to D.

The arms load and unload on arrival, so `navigate` is the only command the keyboard-and-mouse
method ever sends. The compound commands (`deliver`, `weather_delivery`,
`sequential_delivery`) stay in the product; the procedures use them only where the paper did.

The API, for the participant model, the judge and the station:

- `allowed_actions(method, task)`: the command actions a method may send in a task;
  `check_action` raises `ProcedureViolation` for any other.
- `procedure_for(method, task, plan, fleet)`: the task's `Procedure`, a tuple of `Step`s;
  `Procedure.must_observe_before(k)` is what the participant must have observed before
  step k, and `Procedure.ready(observed, done)` the steps that may be taken now.
- `conformance(procedure, entries)`: the judge's check that the orders in a task's log came
  in an order the procedure allows (an order before what it must follow was visible fails).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Literal

from vahr.domain import WEATHER_ZONES
from vahr.domain.invocation import INVOCATION_NAME
from vahr.experiment.eventlog import Kind
from vahr.experiment.tasks import SEQUENCE_ZONE

if TYPE_CHECKING:
    from collections.abc import Collection, Iterable

    from vahr.domain import Fleet
    from vahr.experiment.eventlog import LogEntry
    from vahr.experiment.tasks import Plan

Method = Literal["vahr", "keyboard"]
# Recorded in a session's header: the judge checks conformance only for sessions run with it.
PROCEDURE = "paper"
# A step's zone when it is the zone the weather calls for, as the assistant said it.
WEATHER = "WEATHER"
LOADING = "LOADING"

_ALLOWED: dict[tuple[str, str], frozenset[str]] = {
    ("vahr", "I"): frozenset({"navigate"}),
    ("vahr", "II"): frozenset({"weather_delivery"}),
    ("vahr", "III"): frozenset({"sequential_delivery"}),
    ("keyboard", "I"): frozenset({"navigate"}),
    ("keyboard", "II"): frozenset({"navigate"}),
    ("keyboard", "III"): frozenset({"navigate"}),
}
# The skill's intents each voice step uses (the keyboard method asks one question in task II).
INTENTS: dict[tuple[str, str], frozenset[str]] = {
    ("vahr", "I"): frozenset({"NavigateIntent"}),
    ("vahr", "II"): frozenset({"WeatherDeliveryIntent"}),
    ("vahr", "III"): frozenset({"SequentialDeliveryIntent"}),
    ("keyboard", "I"): frozenset(),
    ("keyboard", "II"): frozenset({"WeatherIntent"}),
    ("keyboard", "III"): frozenset(),
}


class ProcedureViolation(ValueError):
    """An order the paper's procedure does not allow (a compound command in a keyboard
    session, an order before what it must follow was observed)."""


ObservationEvent = Literal["loaded", "delivered", "spoke", "answered"]


@dataclass(frozen=True)
class Observation:
    """Something the participant must have noticed before a step.

    - `loaded`, `delivered`: seen on the screen (the participant must look);
    - `spoke`: the robot's spoken exchange with the assistant has ended (heard);
    - `answered`: the assistant answered the participant's weather question for `thing`.
    """

    thing: str
    event: ObservationEvent

    @property
    def by_sight(self) -> bool:
        return self.event in ("loaded", "delivered")

    def describe(self) -> str:
        return {
            "loaded": f"{self.thing} was loaded",
            "delivered": f"{self.thing} delivered",
            "spoke": f"{self.thing} finished talking to the assistant",
            "answered": f"the assistant said the weather for {self.thing}",
        }[self.event]


@dataclass(frozen=True)
class Step:
    """One thing the participant does: an order to robots, or a question to the assistant."""

    index: int
    things: tuple[str, ...]  # the robots the step is for (two for one sequential delivery)
    channel: Literal["voice", "click"]
    action: str | None  # the command action it sends; None for a question
    zone: str | None  # a zone id, WEATHER (resolved from the answer heard), or None
    requires: tuple[Observation, ...] = ()
    utterance: str | None = None  # what the participant says (voice steps)

    @property
    def thing(self) -> str:
        return self.things[0]

    @property
    def is_question(self) -> bool:
        return self.action is None

    @property
    def label(self) -> str:
        """How the step is named in the log (`text` of its interaction)."""
        if self.utterance is not None:
            return self.utterance
        return f"{self.thing} {self.action} zone={self.zone}"

    def resolved(self, weather: str | None) -> Step:
        """The step with WEATHER replaced by the zone for `weather` (as heard)."""
        if self.zone != WEATHER:
            return self
        if weather not in WEATHER_ZONES:
            raise ProcedureViolation(f"{self.label}: no weather has been heard yet")
        return replace(self, zone=WEATHER_ZONES[weather])


@dataclass(frozen=True)
class Procedure:
    method: str
    task: str
    steps: tuple[Step, ...]

    @property
    def allowed_actions(self) -> frozenset[str]:
        return allowed_actions(self.method, self.task)

    def must_observe_before(self, k: int) -> tuple[Observation, ...]:
        """What the participant must have observed before taking step `k`."""
        return self.steps[k].requires

    def ready(self, observed: Collection[Observation], done: Collection[int]) -> list[Step]:
        """Steps not yet done whose observations have all been made, in procedure order."""
        return [
            step
            for step in self.steps
            if step.index not in done and all(need in observed for need in step.requires)
        ]

    @property
    def watched(self) -> frozenset[Observation]:
        """Every observation by sight some step waits for: what the participant looks for."""
        return frozenset(o for step in self.steps for o in step.requires if o.by_sight)


def allowed_actions(method: str, task: str) -> frozenset[str]:
    """The command actions `method` may send in `task` (empty for an unknown pair)."""
    return _ALLOWED.get((method, task), frozenset())


def check_action(method: str, task: str | None, action: str) -> None:
    """Raise ProcedureViolation unless `method` may send `action` in `task`."""
    if task is None:
        raise ProcedureViolation("no task is running: orders are given during a task")
    allowed = allowed_actions(method, task)
    if action not in allowed:
        uses = ", ".join(sorted(allowed)) or "no command"
        raise ProcedureViolation(
            f"the {method} procedure of task {task} uses {uses}, not {action} "
            "(the paper's procedure; see docs/experiment.md)"
        )


def heard_weather(speech: str) -> str | None:
    """The weather a person hears in the assistant's reply, if it names exactly one."""
    words = set(re.findall(r"[a-z]+", speech.lower()))
    found = [weather for weather in WEATHER_ZONES if weather in words]
    return found[0] if len(found) == 1 else None


def _say(sample: str) -> str:
    """A one-shot request to the skill, wake word and invocation name included."""
    return f"Alexa, ask {INVOCATION_NAME} {sample}"


def _zone_words(fleet: Fleet, zone: str) -> str:
    return fleet.zone(zone).spoken[0]


def _navigation(
    method: str, fleet: Fleet | None, thing: str, zone: str, requires: tuple[Observation, ...]
) -> Step:
    utterance = None
    if method == "vahr" and fleet is not None:  # the voice procedures never use WEATHER
        utterance = _say(f"to navigate {fleet.spoken_name(thing)} to {_zone_words(fleet, zone)}")
    channel: Literal["voice", "click"] = "voice" if method == "vahr" else "click"
    return Step(0, (thing,), channel, "navigate", zone, requires, utterance)


def _numbered(steps: Iterable[Step]) -> tuple[Step, ...]:
    return tuple(replace(step, index=index) for index, step in enumerate(steps))


def _task_one(method: str, plan: Plan, fleet: Fleet | None) -> list[Step]:
    goal = plan.goal("I")
    steps = [_navigation(method, fleet, thing, LOADING, ()) for thing in goal.zones]
    steps += [
        _navigation(method, fleet, thing, zone, (Observation(thing, "loaded"),))
        for thing, zone in goal.zones.items()
    ]
    return steps


def _task_two(method: str, plan: Plan, fleet: Fleet | None) -> list[Step]:
    things = list(plan.goal("II").zones)
    if method == "vahr":
        steps: list[Step] = []
        for position, thing in enumerate(things):
            # Two robots talking to one Echo at once would talk over each other: the next
            # request waits until the previous robot's exchange has ended.
            requires = (Observation(things[position - 1], "spoke"),) if position else ()
            utterance = (
                _say(f"to have {fleet.spoken_name(thing)} deliver based on the weather")
                if fleet is not None
                else None
            )
            steps.append(Step(0, (thing,), "voice", "weather_delivery", None, requires, utterance))
        return steps
    question = _say("what is the weather")
    steps = [Step(0, (thing,), "voice", None, None, (), question) for thing in things]
    steps += [_navigation(method, fleet, thing, LOADING, ()) for thing in things]
    steps += [
        _navigation(
            method,
            fleet,
            thing,
            WEATHER,
            (Observation(thing, "loaded"), Observation(thing, "answered")),
        )
        for thing in things
    ]
    return steps


def _task_three(method: str, plan: Plan, fleet: Fleet | None) -> list[Step]:
    goal = plan.goal("III")
    first, second = goal.order[0], goal.order[1]
    zone = goal.zones.get(first, SEQUENCE_ZONE)
    if method == "vahr":
        utterance = None
        if fleet is not None:
            name, words = fleet.spoken_name, _zone_words(fleet, zone)
            utterance = _say(
                f"to have {name(first)} deliver to {words} "
                f"and then {name(second)} deliver to {words}"
            )
        return [Step(0, (first, second), "voice", "sequential_delivery", zone, (), utterance)]
    first_done = Observation(first, "delivered")
    return [
        _navigation(method, fleet, first, LOADING, ()),
        _navigation(method, fleet, first, zone, (Observation(first, "loaded"),)),
        _navigation(method, fleet, second, LOADING, (first_done,)),
        _navigation(method, fleet, second, zone, (first_done, Observation(second, "loaded"))),
    ]


def procedure_for(method: str, task: str, plan: Plan, fleet: Fleet | None) -> Procedure:
    """The paper's procedure for `method` in `task`, with this session's zones. Without a
    fleet the voice steps carry no utterance (the judge needs none)."""
    if (method, task) not in _ALLOWED:
        raise ValueError(f"no procedure for method {method!r} in task {task!r}")
    build = {"I": _task_one, "II": _task_two, "III": _task_three}[task]
    return Procedure(method, task, _numbered(build(method, plan, fleet)))


def _targets(command: dict[str, object], robots: Collection[str]) -> list[str]:
    target = str(command.get("target", ""))
    return list(robots) if target == "fleet" else [target]


def _matches(step: Step, action: object, zone: object) -> bool:
    if step.action != action:
        return False
    if step.zone is None:
        return True
    if step.zone == WEATHER:
        return zone in WEATHER_ZONES.values()
    return bool(step.zone == zone)


def conformance(
    procedure: Procedure, entries: list[LogEntry], robots: Collection[str]
) -> list[str]:
    """Why the orders among a task's `entries` break the procedure (empty if they do not).

    Each order (a command from the participant, not one robot's to another) must be one the
    method may send in the task, and the first step it can stand for must not wait on
    something visible (a robot loaded, a robot delivered) that had not yet happened. An order
    that stands for no step (sent twice, to a wrong zone) breaks nothing here: what it
    causes is judged by the deliveries.
    """
    seen: set[Observation] = set()
    taken: set[tuple[int, str]] = set()
    problems: list[str] = []
    for entry in entries:
        data = entry.data
        if entry.kind == Kind.ROBOT_EVENT and data.get("event") in ("loaded", "delivered"):
            seen.add(Observation(str(data.get("thing")), data["event"]))
            continue
        if entry.kind != Kind.COMMAND or str(data.get("source", "")).startswith("robot:"):
            continue
        action = data.get("action")
        if action not in procedure.allowed_actions:
            uses = ", ".join(sorted(procedure.allowed_actions)) or "no command"
            problems.append(
                f"{action} was sent, but the {procedure.method} procedure of task "
                f"{procedure.task} uses {uses}"
            )
            continue
        params = data.get("params") if isinstance(data.get("params"), dict) else {}
        zone = params.get("zone") if isinstance(params, dict) else None
        for thing in _targets(data, robots):
            step = next(
                (
                    s
                    for s in procedure.steps
                    if thing in s.things
                    and (s.index, thing) not in taken
                    and _matches(s, action, zone)
                ),
                None,
            )
            if step is None:
                continue
            taken.add((step.index, thing))
            missing = [o for o in step.requires if o.by_sight and o not in seen]
            if missing:
                where = f" to {zone}" if zone else ""
                problems.append(
                    f"{thing} was sent{where} before {' and '.join(o.describe() for o in missing)}"
                )
    return problems
