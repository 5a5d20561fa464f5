"""DeliverIntent: "have placebot one deliver a package to zone B"."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog, prompts
from skill.handlers.send import send_and_report

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime
    from skill.task_desk import TaskDesk


class DeliverIntentHandler(AbstractRequestHandler):
    """Load a package at the loading zone and carry it to a zone."""

    def __init__(self, runtime: SkillRuntime, desk: TaskDesk | None = None) -> None:
        self.runtime = runtime
        self.desk = desk

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("DeliverIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        robot = dialog.robot(handler_input, self.runtime, "robot")
        if robot.id is None:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        zone = dialog.zone(handler_input, self.runtime, "zone")
        if dialog.delivery_zone_problem(zone):
            return dialog.ask_zone(
                handler_input,
                self.runtime,
                zone,
                prompts.ASK_DELIVERY_ZONE,
                robot_id=robot.id,
                deliverable=True,
                preface=prompts.LOADING_IS_NOT_A_DESTINATION if zone.id else "",
            )
        return send_and_report(
            handler_input, self.runtime, "deliver", robot.id, {"zone": zone.id}, desk=self.desk
        )
