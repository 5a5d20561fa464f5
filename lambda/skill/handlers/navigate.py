"""NavigateIntent: "send placebot one to zone A", "move all robots to the loading zone"."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog
from skill.handlers.send import send_and_report

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime
    from skill.task_desk import TaskDesk


class NavigateIntentHandler(AbstractRequestHandler):
    """Send one robot or the whole fleet to a zone."""

    def __init__(self, runtime: SkillRuntime, desk: TaskDesk | None = None) -> None:
        self.runtime = runtime
        self.desk = desk

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("NavigateIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        robot = dialog.robot(handler_input, self.runtime, "robot")
        if robot.id is None:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        zone = dialog.zone(handler_input, self.runtime, "zone")
        if zone.id is None:
            return dialog.ask_zone(handler_input, self.runtime, zone)
        return send_and_report(
            handler_input, self.runtime, "navigate", robot.id, {"zone": zone.id}, desk=self.desk
        )
