"""OutOfServiceIntent and BackInServiceIntent: "take rover one out of service", "take the
rovers out of service", "put rover one back in service".

The dispatcher keeps which robots are out of service (`TaskDesk.set_service`): such a
robot gets no task, the task it held goes to another robot or waits, and a command naming
it is not sent (`skill.service_guard`). Changing the service of robots is a supervisor's
command (`skill.access`), confirmed by its asker first (`skill.guard.confirm_first`) and
recorded in the trail.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import battery_speech, deeds, dialog, prompts
from skill.guard import confirm_first
from skill.handlers.desk_intent import DeskIntentHandler
from skill.responses import answer
from skill.task_desk import TaskRefused
from skill.vocabulary import FLEET

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from vahr.dispatch import ServiceChange


class _ServiceHandler(DeskIntentHandler):
    """Take the robots named (a robot, a group, or the fleet) out of service or back."""

    in_service = False

    def handle(self, handler_input: HandlerInput) -> Response:
        group, refusal = dialog.group(handler_input, self.runtime)
        if refusal:
            return answer(handler_input, refusal)
        things = next((list(g.robots) for g in self.runtime.fleet.groups if g.id == group), [])
        if not things:
            robot = dialog.robot(handler_input, self.runtime, "robot")
            if robot.id is None:
                return dialog.ask_robot(handler_input, self.runtime, robot)
            fleet = self.runtime.fleet.robot_things
            things = list(fleet) if robot.id == FLEET else [robot.id]
        if self.desk is None:
            return answer(handler_input, prompts.NO_SERVICE_DESK)
        question = confirm_first(handler_input, self.runtime)
        if question is not None:
            return question
        changes: list[ServiceChange] = []
        for thing in things:
            try:
                changes.append(self.desk.set_service(thing, in_service=self.in_service))
            except TaskRefused as err:
                deeds.failed(f"the dispatcher refused: {err}")
                if err.status == 404 and err.error is None:  # no service routes here
                    return answer(handler_input, prompts.NO_SERVICE_DESK)
                return answer(handler_input, prompts.DISPATCH_REFUSED.format(reason=str(err)))
        done = deeds.current()
        done.changed = any(change.changed for change in changes)
        for change in changes:
            if change.thing not in done.robots:
                done.robots.append(change.thing)
            for task in [*change.reassigned, *change.given]:
                if task.thing is not None:
                    done.add(task.id, [task.thing])
        return answer(
            handler_input, battery_speech.service_report(self.runtime.vocabulary, changes)
        )


class OutOfServiceIntentHandler(_ServiceHandler):
    """ "take rover one out of service": it gets no task and moves for no command."""

    intent_name = "OutOfServiceIntent"
    in_service = False


class BackInServiceIntentHandler(_ServiceHandler):
    """ "put rover one back in service": it takes tasks again."""

    intent_name = "BackInServiceIntent"
    in_service = True
