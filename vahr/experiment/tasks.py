"""The paper's three tasks and the seeded plan of one session.

- Task I: each robot delivers its package to the zone it is assigned (drawn at random).
- Task II: each robot delivers to A if the weather is sunny, C if it is rainy (the weather
  is drawn at random and stored in the experiment thing's shadow, which the skill answers
  from). With the voice method each robot asks the assistant itself; with the keyboard and
  mouse the participant asks the assistant, once per robot, as the paper describes it.
- Task III: both robots deliver to zone D, placebot1 first; the LED lights only on success.

The plan is a pure function of the seed and the fleet, so a session can be replayed and a
resumed session finds the same assignments.
"""

from __future__ import annotations

import hashlib
import random
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

from vahr.domain import WEATHER_ZONES, WEATHERS
from vahr.errors import VahrError
from vahr.protocol import ExperimentState

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.protocol import Weather

TaskId = Literal["I", "II", "III"]
TASKS: tuple[TaskId, ...] = ("I", "II", "III")
METHODS = ("vahr", "keyboard")
SEQUENCE_ZONE = "D"

TASK_TITLES = {
    "I": "deliver each package to its assigned zone",
    "II": "each robot delivers according to the weather (sunny: A, rainy: C)",
    "III": "both robots deliver to zone D, placebot1 first",
}


@dataclass(frozen=True)
class TaskGoal:
    """What one task asks for: the zone each robot must deliver to, and in which order."""

    task: TaskId
    zones: dict[str, str]
    # Robots that must deliver in this order (task III); empty when order does not matter.
    order: tuple[str, ...] = ()

    def to_json(self) -> dict[str, Any]:
        return {"task": self.task, "zones": dict(self.zones), "order": list(self.order)}

    @classmethod
    def from_json(cls, body: dict[str, Any]) -> TaskGoal:
        return cls(task=body["task"], zones=dict(body["zones"]), order=tuple(body["order"]))


@dataclass(frozen=True)
class Plan:
    """One session's randomized conditions and the goal of each task."""

    seed: int
    assignments: dict[str, str]
    weather: Weather
    # The first robot to deliver by the weather (logs from before task II had both robots
    # deliver name only this one in their task II goal).
    weather_robot: str
    goals: dict[str, TaskGoal] = field(default_factory=dict)

    def goal(self, task: str) -> TaskGoal:
        return self.goals[task]

    def experiment_state(self, session: str) -> ExperimentState:
        """The experiment thing's reported state for this plan."""
        return ExperimentState(weather=self.weather, assignments=self.assignments, session=session)

    def to_json(self) -> dict[str, Any]:
        return {
            "seed": self.seed,
            "assignments": dict(self.assignments),
            "weather": self.weather,
            "weather_robot": self.weather_robot,
            "goals": {task: goal.to_json() for task, goal in self.goals.items()},
        }

    @classmethod
    def from_json(cls, body: dict[str, Any]) -> Plan:
        return cls(
            seed=int(body["seed"]),
            assignments=dict(body["assignments"]),
            weather=body["weather"],
            weather_robot=body["weather_robot"],
            goals={task: TaskGoal.from_json(goal) for task, goal in body["goals"].items()},
        )


def default_seed(participant: str, method: str, trial: int) -> int:
    """A stable seed for a session when none is given, so reruns draw the same plan."""
    digest = hashlib.sha256(f"{participant}\x00{method}\x00{trial}".encode()).digest()
    return int.from_bytes(digest[:4], "big")


def delivery_zones(fleet: Fleet) -> list[str]:
    """Zones with an unloading arm: where packages can be delivered."""
    return [zone.id for zone in fleet.zones if zone.arm == "unloader"]


# The delivery zones the tasks name: task II's weather zones and task III's.
NEEDED_ZONES = (*sorted(set(WEATHER_ZONES.values())), SEQUENCE_ZONE)


class UnfitFleet(VahrError):
    """The fleet lacks robots or zones the paper's tasks need."""


def require_fit_fleet(fleet: Fleet) -> None:
    """Raise UnfitFleet, in one line saying what the tasks need and what the fleet lacks,
    unless it has two robots (task III's first and second) and the delivery zones
    NEEDED_ZONES (zones with an unloading arm)."""
    lacking = [zone for zone in NEEDED_ZONES if zone not in delivery_zones(fleet)]
    missing = (
        [f"delivery zone{'s' if len(lacking) > 1 else ''} {_words(lacking)}"] if lacking else []
    )
    if len(fleet.robots) < 2:
        missing.append("a second robot")
    if missing:
        raise UnfitFleet(
            f"the paper's tasks need two robots and delivery zones {_words(NEEDED_ZONES)} "
            f"(zones with arm: unloader); this fleet lacks {' and '.join(missing)}"
        )


def _words(items: tuple[str, ...] | list[str]) -> str:
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} and {items[-1]}"


def draw_plan(fleet: Fleet, seed: int) -> Plan:
    """Draw the zone assignments (distinct zones when there are enough) and the weather."""
    require_fit_fleet(fleet)
    rng = random.Random(seed)
    zones = delivery_zones(fleet)
    robots = list(fleet.robot_things)
    if len(zones) >= len(robots):
        assigned = rng.sample(zones, len(robots))
    else:
        assigned = [rng.choice(zones) for _ in robots]
    assignments = dict(zip(robots, assigned, strict=True))
    weather: Weather = rng.choice(WEATHERS)
    first, second = robots[0], robots[1]
    goals = {
        "I": TaskGoal(task="I", zones=dict(assignments)),
        "II": TaskGoal(
            task="II", zones={first: WEATHER_ZONES[weather], second: WEATHER_ZONES[weather]}
        ),
        "III": TaskGoal(
            task="III", zones={first: SEQUENCE_ZONE, second: SEQUENCE_ZONE}, order=(first, second)
        ),
    }
    return Plan(
        seed=seed, assignments=assignments, weather=weather, weather_robot=first, goals=goals
    )
