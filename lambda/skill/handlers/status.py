"""StatusIntent: "where is placebot one", "where are the robots"; ProblemRobotsIntent:
"which robots are stuck?".

A small fleet is answered from its shadows, one sentence per robot, as long as that fits
in `speech.MAX_WORDS` words (the paper's two robots always do); past that, the answer is a
summary: counts by status, then the robots in trouble by name. A fleet larger than
`fleet_question.SHADOW_READ_MAX` is never read shadow by shadow: the fleet index answers in
a handful of calls whatever the fleet's size.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog, speech
from skill.errors import GatewayError
from skill.fleet_question import FleetQuestion
from skill.responses import answer
from skill.vocabulary import FLEET

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response


class StatusIntentHandler(FleetQuestion, AbstractRequestHandler):
    """Speak one robot's state, or the fleet's when none (or the fleet) is named."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("StatusIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        robot = dialog.robot(handler_input, self.runtime, "robot")
        if robot.unresolved:
            return dialog.ask_robot(handler_input, self.runtime, robot)
        vocabulary = self.runtime.vocabulary
        if robot.id not in (None, FLEET):
            read = self.runtime.robots.shadows([str(robot.id)])[str(robot.id)]
            if read.error is not None:
                raise GatewayError(read.error)
            return answer(handler_input, speech.robot_status(vocabulary, read))
        reads = self.read_all()
        if reads is not None:
            every_robot = speech.status_report(vocabulary, reads)
            if speech.words(every_robot) <= speech.MAX_WORDS:
                return answer(handler_input, every_robot)
        return answer(handler_input, speech.fleet_summary(vocabulary, self.state(reads)))


class ProblemRobotsIntentHandler(FleetQuestion, AbstractRequestHandler):
    """Name the robots that are stuck, have failed or are offline."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("ProblemRobotsIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        state = self.state(self.read_all())
        return answer(handler_input, speech.problem_report(self.runtime.vocabulary, state))
