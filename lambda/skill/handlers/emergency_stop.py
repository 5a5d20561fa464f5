"""EmergencyStopIntent: halt one robot, or every robot when none is named."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog
from skill.handlers.send import send_and_report
from skill.vocabulary import FLEET

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime


class EmergencyStopIntentHandler(AbstractRequestHandler):
    """Publish `stop` at once; distinct from AMAZON.StopIntent, which only ends the session."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("EmergencyStopIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        robot = dialog.robot(handler_input, self.runtime, "robot")
        # "Emergency stop" with no robot named stops them all: asking "which robot?" first
        # would delay a stop that may be urgent. A name that did not resolve is asked again,
        # since stopping the wrong robots is no answer either.
        if robot.unresolved:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        return send_and_report(handler_input, self.runtime, "stop", robot.id or FLEET)
