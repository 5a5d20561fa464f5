"""StatusIntent: "where is placebot one", "where are the robots"; ProblemRobotsIntent:
"which robots are stuck?".

A small fleet is answered from its shadows, one sentence per robot, as long as that fits
in `speech.MAX_WORDS` words (the paper's two robots always do); past that, the answer is a
summary: counts by status, then the robots in trouble by name. A fleet larger than
`SHADOW_READ_MAX` is never read shadow by shadow: the fleet index answers in a handful of
calls whatever the fleet's size.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import dialog, fleet_status, speech
from skill.errors import GatewayError
from skill.iot_fleet_index import IotFleetIndex
from skill.responses import answer
from skill.vocabulary import FLEET

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.fleet_status import FleetState
    from skill.iot_fleet_index import FleetIndex
    from skill.robots import ShadowRead
    from skill.runtime import SkillRuntime

# The most robots whose shadows a status question reads one by one. Past it the reads
# cost more than the index's three to five calls (each read is a billable GetThingShadow,
# and 25 of them take as long as the whole answer may), and one sentence per robot would
# pass the word bound anyway: a robot's sentence is 4 to 15 words.
SHADOW_READ_MAX = 25


class _FleetQuestion:
    """What both intents share: the fleet's shadows or its index, and the index's client,
    made on first use (a two-robot skill never needs it)."""

    def __init__(self, runtime: SkillRuntime, fleet_index: FleetIndex | None = None) -> None:
        self.runtime = runtime
        self._index = fleet_index

    @property
    def index(self) -> FleetIndex:
        if self._index is None:
            self._index = IotFleetIndex.from_config(self.runtime.config)
        return self._index

    def read_all(self) -> list[ShadowRead] | None:
        """Every robot's shadow, for a small fleet (None for a large one)."""
        things = list(self.runtime.fleet.robot_things)
        if len(things) > SHADOW_READ_MAX:
            return None
        reads = self.runtime.robots.shadows(things)
        if all(read.error is not None for read in reads.values()):
            # Nothing could be read at all: that is an outage, not a robot's state.
            raise GatewayError("; ".join(str(read.error) for read in reads.values()))
        return list(reads.values())

    def state(self, reads: list[ShadowRead] | None) -> FleetState:
        if reads is not None:
            return fleet_status.from_shadows(reads)
        return fleet_status.from_index(self.index, len(self.runtime.fleet.robots))


class StatusIntentHandler(_FleetQuestion, AbstractRequestHandler):
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


class ProblemRobotsIntentHandler(_FleetQuestion, AbstractRequestHandler):
    """Name the robots that are stuck, have failed or are offline."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("ProblemRobotsIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        state = self.state(self.read_all())
        return answer(handler_input, speech.problem_report(self.runtime.vocabulary, state))
