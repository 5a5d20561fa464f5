"""What kind of action a request is, decided from the intent and its slots alone (pure).

`INTENT_RULES` is the table: each intent's kind (`vahr.domain.people.ActionKind`), and the
slots that can widen it to the whole fleet. A robot slot that names every robot ("all
robots") makes a command fleet-wide; so does a dispatch to more robots than the fleet's
`confirmation.group_threshold`, or to every robot of the fleet. A slot that did not
resolve (a name misheard, several robots the words fit) never widens anything: the handler
asks which robot was meant, and the answer is classified again.

An intent the table does not name is fleet-wide, the most guarded kind: a new intent is
classified here before anyone but a supervisor can use it (a test holds every intent of the
interaction model to an entry). Zone closures and service changes are listed already.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

from skill.slots import read_slot, spoken_number
from skill.vocabulary import FLEET
from vahr.domain import FLEET_GROUP
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.domain.text import normalize

if TYPE_CHECKING:
    from ask_sdk_model import Intent

    from skill.vocabulary import Vocabulary
    from vahr.domain import Fleet
    from vahr.domain.people import ActionKind

# A command to more robots than this is fleet-wide unless the fleet file says otherwise.
DEFAULT_GROUP_THRESHOLD = 3


class IntentRule(NamedTuple):
    """How one intent is classified: its kind, the slots naming robots (the fleet named in
    one makes it fleet-wide), and whether its count and group slots size it."""

    kind: ActionKind
    robot_slots: tuple[str, ...] = ()
    sized: bool = False


QUESTION = IntentRule("question")
FLEET_WIDE = IntentRule("fleet")

INTENT_RULES: dict[str, IntentRule] = {
    # Robots and tasks: an operator's, fleet-wide when the fleet is named.
    "NavigateIntent": IntentRule("command", ("robot",)),
    "DeliverIntent": IntentRule("command", ("robot",)),
    "WeatherDeliveryIntent": IntentRule("command", ("robot",)),
    "SequentialDeliveryIntent": IntentRule("command", ("firstRobot", "secondRobot")),
    "CorrectionIntent": IntentRule("command", ("robot",)),
    "UndoIntent": IntentRule("command"),
    "CancelTaskIntent": IntentRule("command"),
    "ChargeIntent": IntentRule("command", ("robot",)),
    # A dispatch is sized by its count or its group.
    "FleetNavigateIntent": IntentRule("command", sized=True),
    # Robots the speaker did not count: every idle one, every one in a zone.
    "IdleRobotsIntent": FLEET_WIDE,
    "ZoneRobotsIntent": FLEET_WIDE,
    # Service changes and closures: a supervisor's, confirmed first.
    "CancelAllTasksIntent": FLEET_WIDE,
    "CloseZoneIntent": FLEET_WIDE,
    "OpenZoneIntent": FLEET_WIDE,
    "OutOfServiceIntent": FLEET_WIDE,
    "BackInServiceIntent": FLEET_WIDE,
    # Anyone may stop the robots, at once.
    "EmergencyStopIntent": IntentRule("stop"),
    # Questions, and the conversation itself.
    "StatusIntent": QUESTION,
    "ProblemRobotsIntent": QUESTION,
    "WeatherIntent": QUESTION,
    "TaskQueueIntent": QUESTION,
    "BatteryIntent": QUESTION,
    "AMAZON.HelpIntent": QUESTION,
    "AMAZON.CancelIntent": QUESTION,
    "AMAZON.StopIntent": QUESTION,
    "AMAZON.NavigateHomeIntent": QUESTION,
    FALLBACK_INTENT: QUESTION,
    "AMAZON.YesIntent": QUESTION,
    "AMAZON.NoIntent": QUESTION,
}
# Requests that are no intent: opening the skill, the session ending.
REQUEST_KINDS: dict[str, ActionKind] = {
    "LaunchRequest": "question",
    "SessionEndedRequest": "question",
}


def classify(
    intent: Intent,
    vocabulary: Vocabulary,
    threshold: int = DEFAULT_GROUP_THRESHOLD,
) -> ActionKind:
    """The kind of action `intent` asks for (see the module's docstring)."""
    rule = INTENT_RULES.get(str(intent.name), FLEET_WIDE)
    if rule.kind != "command":
        return rule.kind
    for slot in rule.robot_slots:
        reading = read_slot(intent, slot, vocabulary.robot_ids, vocabulary.robot_id)
        if reading.id == FLEET:
            return "fleet"
    if rule.sized:
        robots = robots_asked_for(intent, vocabulary.fleet)
        if robots > threshold or (robots >= len(vocabulary.fleet.robots) > 1):
            return "fleet"
    return "command"


def robots_asked_for(intent: Intent, fleet: Fleet) -> int:
    """How many robots a dispatch asks for: the count said, else the group's size, else
    one ("send a robot"). A count or group that did not resolve counts as one."""
    groups = {group.id: group for group in fleet.groups if group.id != FLEET_GROUP}
    names = {normalize(name): gid for gid, group in groups.items() for name in group.spoken}
    group = read_slot(intent, "group", groups, lambda heard: names.get(normalize(heard)))
    count = read_slot(
        intent, "count", {str(n) for n in range(1, 1000)}, lambda heard: _as_id(heard)
    )
    if count.id is not None:
        return int(count.id)
    if count.heard is not None and (said := spoken_number(count.heard)) is not None:
        return said
    if group.id is not None:
        return len(groups[group.id].robots)
    return 1


def _as_id(heard: str) -> str | None:
    value = spoken_number(heard)
    return str(value) if value is not None else None
