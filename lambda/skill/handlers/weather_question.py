"""WeatherIntent: "what is the weather" answers the current experiment's weather."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import prompts
from skill.experiment_weather import current_weather
from skill.responses import answer

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime


class WeatherIntentHandler(AbstractRequestHandler):
    """Answer "The weather is sunny." or "The weather is rainy." (robots listen for these)."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("WeatherIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        weather = current_weather(
            self.runtime.gateway, self.runtime.fleet.experiment_thing, self.runtime.rng
        )
        return answer(handler_input, prompts.WEATHER[weather])
