"""BatteryIntent: "how much battery does rover one have", "which robots are below thirty
percent", "which robots are low on battery"; ChargeIntent: "send rover one to charge".

The charge is each robot's `reported.battery`, read from the shadows of a small fleet and
asked of the fleet index for a large one (`fleet_question`): how many are under a percent
(a range on the indexed charge) and a page of them to name the lowest, or for the whole
fleet how many are low and how many charge. Sending a robot to charge is the dispatcher's
(`TaskDesk.charge`): it holds the nearest free charger for the robot, as it does when a
robot low on charge goes by itself (docs/dispatch.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

from skill import battery_speech, deeds, dialog, prompts
from skill.dialog import _intent
from skill.fleet_question import FleetQuestion
from skill.handlers.desk_intent import DeskIntentHandler
from skill.iot_fleet_index import BATTERY_CHARGING_FIELD, BATTERY_PERCENT_FIELD, SEARCH_MAX
from skill.responses import answer
from skill.service_guard import out_of_service
from skill.slots import read_slot, spoken_number
from skill.task_desk import TaskRefused
from skill.vocabulary import FLEET, capitalise

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response


PERCENTS = frozenset(str(n) for n in range(1, 101))


class BatteryIntentHandler(FleetQuestion, AbstractRequestHandler):
    """The charge of one robot, of every robot, or of those below a percent."""

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
        threshold = round(runtime.fleet.battery_plan.charge_below)
        reads = self.read_all()
        if robot.id == FLEET and percent.missing:
            if reads is None:
                return answer(handler_input, self._fleet_counts(threshold))
            return answer(handler_input, battery_speech.every_battery(runtime.vocabulary, reads))
        # "which robots are low on battery": under the fleet's threshold.
        level = int(percent.id) if percent.id is not None else threshold
        if reads is None:
            return answer(handler_input, self._below_in_index(level))
        return answer(handler_input, battery_speech.below(runtime.vocabulary, level, reads))

    def _below_in_index(self, level: int) -> str:
        query = f"{BATTERY_PERCENT_FIELD}<{level}"
        found = self.index.search(query, SEARCH_MAX)
        count = len(found) if len(found) < SEARCH_MAX else self.index.count(query)
        return battery_speech.below_in_index(self.runtime.vocabulary, level, count, found)

    def _fleet_counts(self, threshold: int) -> str:
        low = self.index.count(f"{BATTERY_PERCENT_FIELD}<{threshold}")
        charging = self.index.count(f"{BATTERY_CHARGING_FIELD}:true")
        total = len(self.runtime.fleet.robots)
        return battery_speech.fleet_counts(total, threshold, low, charging)


class ChargeIntentHandler(DeskIntentHandler):
    """Send one robot to the nearest free charger now."""

    intent_name = "ChargeIntent"

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
