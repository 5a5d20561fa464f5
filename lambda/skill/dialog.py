"""Reading ROBOT, ZONE and GROUP slots against the fleet, and asking again when they fall
short.

A value the words fit several ways ("zone b" heard as B or D) is asked about by name
("Zone B or zone D?") rather than acted on; the answer fills the slot afresh. Zones named by
letters that sound alike may also be answered by their spelling-alphabet words, which the
reprompt offers ("You can also say bravo or delta."), as does the question when the skill
has asked about the same command before.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import prompts
from skill.catalog import current_locale
from skill.responses import answer, elicit, may_ask_again, questions_asked
from skill.slots import read_slot
from skill.vocabulary import LOADING, capitalise, join_choices
from vahr.domain import FLEET_GROUP
from vahr.domain.fleet import spoken_in
from vahr.domain.text import normalize

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Intent, IntentRequest, Response

    from skill.runtime import SkillRuntime
    from skill.slots import SlotReading


def _intent(handler_input: HandlerInput) -> Intent:
    request: IntentRequest = handler_input.request_envelope.request  # type: ignore[assignment]
    intent = request.intent
    if intent is None:  # an IntentRequest always names its intent; this is for the types
        raise ValueError("the IntentRequest carries no intent")
    return intent


def robot(handler_input: HandlerInput, runtime: SkillRuntime, name: str) -> SlotReading:
    vocabulary = runtime.vocabulary
    return read_slot(_intent(handler_input), name, vocabulary.robot_ids, vocabulary.robot_id)


def zone(handler_input: HandlerInput, runtime: SkillRuntime, name: str) -> SlotReading:
    vocabulary = runtime.vocabulary
    return read_slot(_intent(handler_input), name, runtime.fleet.zone_ids, vocabulary.zone_id)


def group(handler_input: HandlerInput, runtime: SkillRuntime) -> tuple[str | None, str]:
    """The group the `group` slot names (None when none was said), or what to say when the
    fleet has no group of that name."""
    groups = {g.id: g for g in runtime.fleet.groups if g.id != FLEET_GROUP}
    names = {
        normalize(name): g.id
        for g in groups.values()
        for name in [*g.spoken, *spoken_in(g, current_locale())]
    }
    reading = read_slot(
        _intent(handler_input), "group", groups, lambda heard: names.get(normalize(heard))
    )
    if reading.missing:
        return None, ""
    if reading.id is not None:
        return reading.id, ""
    if not groups:
        return None, prompts.NO_GROUPS.format(heard=reading.heard)
    choices = join_choices([group_name(runtime, group_id) for group_id in groups])
    return None, prompts.UNKNOWN_GROUP.format(heard=reading.heard, choices=choices)


def group_name(runtime: SkillRuntime, group_id: str) -> str:
    """A group's first name in the request's language."""
    found = next(g for g in runtime.fleet.groups if g.id == group_id)
    return spoken_in(found, current_locale())[0]


def ask_robot(
    handler_input: HandlerInput,
    runtime: SkillRuntime,
    reading: SlotReading,
    question: str | None = None,
    *,
    include_fleet: bool = True,
    preface: str = "",
) -> Response:
    """Elicit a robot, listing the choices; say first when the last answer was unknown.
    `question` defaults to ASK_ROBOT, read now: in the request's language."""
    question = prompts.ASK_ROBOT if question is None else question
    if reading.choices:
        names = [runtime.vocabulary.robot(thing) for thing in reading.choices]
        return _ask(handler_input, runtime, reading.name, which_of(names))
    # A name the fleet has left unresolved was withheld (the words did not say whose it
    # is), not unknown: the question alone says what is needed.
    if (
        reading.unresolved
        and not preface
        and runtime.vocabulary.robot_id(str(reading.heard)) is None
    ):
        preface = prompts.UNKNOWN_ROBOT.format(heard=reading.heard)
    choices = runtime.vocabulary.robot_choices(include_fleet=include_fleet)
    return _ask(handler_input, runtime, reading.name, preface + question.format(choices=choices))


def _ask(
    handler_input: HandlerInput, runtime: SkillRuntime, slot: str, question: str, hint: str = ""
) -> Response:
    """Elicit `slot` with `question`; `hint` (how else to answer) is in the reprompt, and in
    the question itself once this command was asked about before."""
    # A person who keeps being misheard needs a way out, not a fourth question.
    if not may_ask_again(handler_input):
        return answer(handler_input, prompts.GIVE_UP.format(**runtime.vocabulary.examples()))
    helped = f"{question} {hint}" if hint else question
    asked_before = questions_asked(handler_input) > 1
    return elicit(handler_input, slot, helped if asked_before else question, helped)


def delivery_zone_problem(reading: SlotReading) -> bool:
    """True when a delivery zone is missing, unknown, or the loading zone itself."""
    return reading.id is None or reading.id == LOADING


def ask_zone(
    handler_input: HandlerInput,
    runtime: SkillRuntime,
    reading: SlotReading,
    question: str | None = None,
    *,
    robot_id: str | None = None,
    deliverable: bool = False,
    preface: str = "",
) -> Response:
    """Elicit a zone, listing the choices (only delivery zones when `deliverable`).
    `question` defaults to ASK_ZONE, read now: in the request's language."""
    question = prompts.ASK_ZONE if question is None else question
    heard_as = [z for z in reading.choices if not (deliverable and z == LOADING)]
    if len(heard_as) > 1:
        names = [runtime.vocabulary.zone(zone_id) for zone_id in heard_as]
        hint = spelled_choices(runtime, heard_as)
        return _ask(handler_input, runtime, reading.name, which_of(names), hint)
    if (
        reading.unresolved
        and not preface
        and runtime.vocabulary.zone_id(str(reading.heard)) is None
    ):
        preface = prompts.UNKNOWN_ZONE.format(heard=reading.heard)
    robot_name = runtime.vocabulary.robot(robot_id) if robot_id else ""
    choices = runtime.vocabulary.zone_choices(deliverable=deliverable)
    text = question.format(choices=choices, robot=robot_name)
    return _ask(handler_input, runtime, reading.name, preface + text)


def spelled_choices(runtime: SkillRuntime, zone_ids: list[str]) -> str:
    """ "You can also say bravo or delta." when every zone of the choice answers to a
    spelling-alphabet word, else ""."""
    words = [runtime.vocabulary.spelled(zone_id) for zone_id in zone_ids]
    if not all(words):
        return ""
    return prompts.SPELLED_CHOICES.format(choices=join_choices([str(word) for word in words]))


def which_of(names: list[str]) -> str:
    """The targeted question for a value heard several ways: "Zone B or zone D?"."""
    return capitalise(prompts.ASK_WHICH_OF.format(choices=join_choices(names)))
