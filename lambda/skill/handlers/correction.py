"""CorrectionIntent and UndoIntent: "no, zone b", "I meant placebot two", "not that robot",
"cancel that", "undo" act on the last command this conversation sent (`skill.session`).

A correction sends the same action again with what changed: a new zone to the same robot
(the new command preempts the old one), or the same zone to another robot (the first one
is stopped, only it). "Not that robot" names no robot: in a fleet of two the other robot is
meant, which the skill confirms first (Dialog.ConfirmSlot); otherwise it asks which. An
undo stops the robot (or robots) the last command went to. Every reply says what changed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog, prompts, session, speech
from skill.commands import publication
from skill.guard import confirm_first
from skill.handlers.send import closed_reply
from skill.responses import answer, confirm_slot
from skill.vocabulary import FLEET, capitalise

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Intent, IntentRequest, Response

    from skill.commands import Publication
    from skill.runtime import SkillRuntime
    from skill.session import SentCommand
    from skill.slots import SlotReading
    from skill.task_desk import TaskDesk

CONFIRMED, DENIED = "CONFIRMED", "DENIED"


def _intent(handler_input: HandlerInput) -> Intent:
    request: IntentRequest = handler_input.request_envelope.request  # type: ignore[assignment]
    assert request.intent is not None
    return request.intent


def _slot_confirmation(handler_input: HandlerInput, name: str) -> str:
    slot = (_intent(handler_input).slots or {}).get(name)
    status = slot.confirmation_status if slot is not None else None
    return status.value if status is not None else "NONE"


class CorrectionIntentHandler(AbstractRequestHandler):
    """Redirect the last command to the robot or zone the person meant."""

    def __init__(self, runtime: SkillRuntime, desk: TaskDesk | None = None) -> None:
        self.runtime = runtime
        self.desk = desk

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("CorrectionIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        last = session.recall(handler_input)
        if last is None:
            return answer(handler_input, prompts.NOTHING_TO_CORRECT)
        robot = dialog.robot(handler_input, self.runtime, "robot")
        zone = dialog.zone(handler_input, self.runtime, "zone")
        if robot.unresolved:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        if zone.unresolved:
            return dialog.ask_zone(handler_input, self.runtime, zone)
        target = robot.id
        if target is not None and robot.heard is not None:
            confirmation = _slot_confirmation(handler_input, "robot")
            if confirmation == DENIED:
                return self._ask_which_robot(handler_input, last, robot)
        if target is None and zone.id is None:
            # "Not that robot": the robot was wrong and the person did not say which.
            return self._other_robot(handler_input, last, robot)
        return self._redirect(handler_input, last, target or last.robot, zone.id or last.zone)

    def _other_robot(
        self, handler_input: HandlerInput, last: SentCommand, robot: SlotReading
    ) -> Response:
        others = [thing for thing in self.runtime.fleet.robot_things if thing != last.robot]
        if last.robot != FLEET and len(others) == 1:
            name = self.runtime.vocabulary.robot(others[0])
            question = capitalise(prompts.CONFIRM_OTHER_ROBOT.format(robot=name))
            return confirm_slot(handler_input, "robot", name, question)
        return self._ask_which_robot(handler_input, last, robot)

    def _ask_which_robot(
        self, handler_input: HandlerInput, last: SentCommand, robot: SlotReading
    ) -> Response:
        return dialog.ask_robot(
            handler_input, self.runtime, robot, prompts.ASK_CORRECT_ROBOT, include_fleet=False
        )

    def _redirect(
        self, handler_input: HandlerInput, last: SentCommand, target: str, zone: str | None
    ) -> Response:
        vocabulary = self.runtime.vocabulary
        if zone != last.zone and last.zone is None:
            text = prompts.WEATHER_HAS_NO_ZONE.format(robot=vocabulary.robot(last.robot))
            return answer(handler_input, capitalise(text))
        if (target, zone) == (last.robot, last.zone):
            text = prompts.ALREADY_SO.format(robot=vocabulary.robot(target))
            return answer(handler_input, capitalise(text))
        refused = closed_reply(self.runtime, self.desk, [zone])
        if refused is not None:
            return answer(handler_input, refused)
        question = confirm_first(handler_input, self.runtime)
        if question is not None:
            return question
        params: dict[str, object] | None = {"zone": zone} if zone is not None else None
        items: list[Publication] = []
        if target != last.robot:
            old = vocabulary.robot(last.robot)
            # The robot first sent stops: only it, since the person meant another one.
            items.append(publication(self.runtime.fleet, "stop", last.robot))
        else:
            old = vocabulary.zone(last.zone) if last.zone else vocabulary.robot(last.robot)
        new = publication(self.runtime.fleet, last.action, target, params)
        items.append(new)
        answers = self.runtime.robots.send(items)
        session.remember(handler_input, new)
        reports = " ".join(speech.command_report(vocabulary, item, answers) for item in items)
        return answer(handler_input, prompts.CORRECTED.format(old=old) + reports)


class UndoIntentHandler(AbstractRequestHandler):
    """Stop the robot the last command went to: "cancel that", "undo"."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("UndoIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        last = session.recall(handler_input)
        if last is None:
            return answer(handler_input, prompts.NOTHING_TO_UNDO)
        item = publication(self.runtime.fleet, "stop", last.robot)
        answers = self.runtime.robots.send([item])
        session.forget(handler_input)
        report = speech.command_report(self.runtime.vocabulary, item, answers)
        return answer(handler_input, prompts.UNDONE + report)
