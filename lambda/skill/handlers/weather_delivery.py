"""WeatherDeliveryIntent (the paper's task II): the robot asks the assistant for the weather."""

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


class WeatherDeliveryIntentHandler(AbstractRequestHandler):
    """Have a robot ask for the weather, then deliver to A if sunny or C if rainy."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("WeatherDeliveryIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        robot = dialog.robot(handler_input, self.runtime, "robot")
        if robot.id is None:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        return send_and_report(handler_input, self.runtime, "weather_delivery", robot.id)
