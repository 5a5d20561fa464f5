"""WeatherDeliveryIntent (the paper's task II): the robot asks the assistant for the weather."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog, prompts
from skill.handlers.send import send_and_report
from skill.responses import answer
from vahr.domain.weather import WEATHER_ZONES

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime
    from skill.task_desk import TaskDesk
    from vahr.protocol.shadow import Weather

# The zones a person may say with the request ("deliver to zone a if it's sunny and zone c
# if it's rainy"), by the weather each is for.
RULE_SLOTS: dict[Weather, str] = {"sunny": "sunnyZone", "rainy": "rainyZone"}


class WeatherDeliveryIntentHandler(AbstractRequestHandler):
    """Have a robot ask for the weather, then deliver to A if sunny or C if rainy."""

    def __init__(self, runtime: SkillRuntime, desk: TaskDesk | None = None) -> None:
        self.runtime = runtime
        self.desk = desk

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("WeatherDeliveryIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        if not self._rule_as_robots_follow(handler_input):
            # Robots deliver by the fixed rule only: a robot sent on another would go where
            # the person did not mean.
            vocabulary = self.runtime.vocabulary
            zones = {weather: vocabulary.zone(zone) for weather, zone in WEATHER_ZONES.items()}
            example = vocabulary.examples()["robot"]
            speech = prompts.OTHER_WEATHER_RULE.format(robot=example, **zones)
            return answer(handler_input, speech)
        robot = dialog.robot(handler_input, self.runtime, "robot")
        if robot.id is None:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        return send_and_report(
            handler_input, self.runtime, "weather_delivery", robot.id, desk=self.desk
        )

    def _rule_as_robots_follow(self, handler_input: HandlerInput) -> bool:
        """Whether every zone said for a weather is the one robots deliver to in it."""
        for weather, slot in RULE_SLOTS.items():
            reading = dialog.zone(handler_input, self.runtime, slot)
            if not reading.missing and reading.id != WEATHER_ZONES[weather]:
                return False
        return True
