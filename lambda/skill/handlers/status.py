"""StatusIntent: "where is placebot one", "what are the robots doing"."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog, speech
from skill.errors import GatewayError
from skill.responses import answer
from skill.vocabulary import FLEET

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime


class StatusIntentHandler(AbstractRequestHandler):
    """Speak one robot's state, or every robot's when none (or the fleet) is named."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("StatusIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        robot = dialog.robot(handler_input, self.runtime, "robot")
        if robot.unresolved:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        things = (
            list(self.runtime.fleet.robot_things) if robot.id in (None, FLEET) else [str(robot.id)]
        )
        reads = self.runtime.robots.shadows(things)
        if all(read.error is not None for read in reads.values()):
            # Nothing could be read at all: that is an outage, not a robot's state.
            raise GatewayError("; ".join(str(read.error) for read in reads.values()))
        return answer(
            handler_input, speech.status_report(self.runtime.vocabulary, list(reads.values()))
        )
