"""SequentialDeliveryIntent (the paper's task III): one robot delivers, then the other."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog, prompts, speech
from skill.commands import sequential
from skill.handlers.send import closed_reply, service_reply
from skill.responses import answer
from skill.vocabulary import FLEET, capitalise

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime
    from skill.slots import SlotReading
    from skill.task_desk import TaskDesk


class SequentialDeliveryIntentHandler(AbstractRequestHandler):
    """The first robot delivers at once; the second delivers once the first has delivered."""

    def __init__(self, runtime: SkillRuntime, desk: TaskDesk | None = None) -> None:
        self.runtime = runtime
        self.desk = desk

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("SequentialDeliveryIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        runtime = self.runtime
        first = dialog.robot(handler_input, runtime, "firstRobot")
        if first.id is None or first.id == FLEET:
            return dialog.ask_robot(
                handler_input,
                runtime,
                first,
                prompts.ASK_FIRST_ROBOT,
                include_fleet=False,
                preface=prompts.NEEDS_ONE_ROBOT if first.id == FLEET else "",
            )
        first_zone = dialog.zone(handler_input, runtime, "firstZone")
        if dialog.delivery_zone_problem(first_zone):
            return self._ask_zone(handler_input, first_zone, first.id)
        second = dialog.robot(handler_input, runtime, "secondRobot")
        second_id = second.id
        if second.missing and len(runtime.fleet.robots) == 2:
            # With two robots, "then the other one" needs no question.
            second_id = next(thing for thing in runtime.fleet.robot_things if thing != first.id)
        if second_id is None or second_id in (FLEET, first.id):
            preface = ""
            if second_id == FLEET:
                preface = prompts.NEEDS_ONE_ROBOT
            elif second_id == first.id:
                name = runtime.vocabulary.robot(first.id)
                preface = capitalise(prompts.SAME_ROBOT.format(robot=name))
            return dialog.ask_robot(
                handler_input,
                runtime,
                second,
                prompts.ASK_SECOND_ROBOT,
                include_fleet=False,
                preface=preface,
            )
        second_zone = dialog.zone(handler_input, runtime, "secondZone")
        if dialog.delivery_zone_problem(second_zone):
            return self._ask_zone(handler_input, second_zone, second_id)
        assert first_zone.id is not None and second_zone.id is not None
        refused = service_reply(
            runtime, self.desk, "sequential_delivery", [first.id, second_id]
        ) or closed_reply(runtime, self.desk, [first_zone.id, second_zone.id])
        if refused is not None:
            return answer(handler_input, refused)
        items = sequential(runtime.fleet, first.id, first_zone.id, second_id, second_zone.id)
        answers = runtime.robots.send(items)
        return answer(handler_input, speech.sequential_report(runtime.vocabulary, items, answers))

    def _ask_zone(self, handler_input: HandlerInput, zone: SlotReading, robot_id: str) -> Response:
        return dialog.ask_zone(
            handler_input,
            self.runtime,
            zone,
            prompts.ASK_DELIVERY_ZONE,
            robot_id=robot_id,
            deliverable=True,
            preface=prompts.LOADING_IS_NOT_A_DESTINATION if zone.id else "",
        )
