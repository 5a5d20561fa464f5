"""BatteryIntent: "how much battery does rover one have", "which robots are below thirty
percent", "which robots are low on battery"; ChargeIntent: "send rover one to charge".

The charge is each robot's `reported.battery`; sending a robot to charge is the
dispatcher's (`TaskDesk.charge`): it holds the nearest free charger for the robot, as it
does when a robot low on charge goes by itself (docs/dispatch.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import battery_speech, deeds, dialog, prompts
from skill.dialog import _intent
from skill.responses import answer
from skill.service_guard import out_of_service
from skill.slots import read_slot, spoken_number
from skill.task_desk import TaskRefused
from skill.vocabulary import FLEET, capitalise

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime
    from skill.task_desk import TaskDesk

# The most robots whose batteries are read one shadow at a time (as a status question does).
SHADOW_READ_MAX = 25
PERCENTS = frozenset(str(n) for n in range(1, 101))


class BatteryIntentHandler(AbstractRequestHandler):
    """The charge of one robot, of every robot, or of those below a percent."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("BatteryIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        runtime = self.runtime
        robot = dialog.robot(handler_input, runtime, "robot")
        percent = read_slot(_intent(handler_input), "percent", PERCENTS, _percent)
        if robot.unresolved:
            return dialog.ask_robot(handler_input, runtime, robot)
        if robot.id is not None and robot.id != FLEET:
            [read] = runtime.robots.shadows([robot.id]).values()
            return answer(handler_input, battery_speech.one_battery(runtime.vocabulary, read))
        things = runtime.fleet.robot_things
        if len(things) > SHADOW_READ_MAX:
            return answer(handler_input, prompts.BATTERY_TOO_MANY.format(count=len(things)))
        reads = list(runtime.robots.shadows(things).values())
        if robot.id == FLEET and percent.missing:
            return answer(handler_input, battery_speech.every_battery(runtime.vocabulary, reads))
        level = int(percent.id) if percent.id is not None else None
        if level is None:
            # "which robots are low on battery": under the fleet's threshold.
            level = round(runtime.fleet.battery_plan.charge_below)
        return answer(handler_input, battery_speech.below(runtime.vocabulary, level, reads))


class ChargeIntentHandler(AbstractRequestHandler):
    """Send one robot to the nearest free charger now."""

    def __init__(self, runtime: SkillRuntime, desk: TaskDesk | None) -> None:
        self.runtime = runtime
        self.desk = desk

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name("ChargeIntent")(handler_input))

    def handle(self, handler_input: HandlerInput) -> Response:
        runtime = self.runtime
        robot = dialog.robot(handler_input, runtime, "robot")
        if robot.id is None or robot.id == FLEET:
            return dialog.ask_robot(handler_input, runtime, robot)
        if self.desk is None:
            return answer(handler_input, prompts.NO_SERVICE_DESK)
        out = out_of_service(self.desk, [robot.id])
        if out:
            deeds.failed("out of service")
            return answer(handler_input, battery_speech.refused(runtime.vocabulary, out))
        name = runtime.vocabulary.robot(robot.id)
        try:
            task = self.desk.charge(robot.id)
        except TaskRefused as err:
            deeds.failed(f"the dispatcher refused: {err}")
            if err.error == "no_charger":
                return answer(handler_input, capitalise(prompts.NO_CHARGER.format(robot=name)))
            if err.error == "out_of_service":
                return answer(handler_input, battery_speech.refused(runtime.vocabulary, [robot.id]))
            return answer(handler_input, prompts.DISPATCH_REFUSED.format(reason=str(err)))
        deeds.current().add(task.id, [robot.id])
        zone = runtime.vocabulary.zone(task.zone)
        return answer(handler_input, capitalise(prompts.CHARGE_SENT.format(robot=name, zone=zone)))


def _percent(heard: str) -> str | None:
    number = spoken_number(heard.replace("percent", "").replace("prozent", "").strip())
    return str(number) if number is not None and 1 <= number <= 100 else None
