"""Fleet dispatch by voice: tasks without a robot's name, through the `TaskDesk` port.

"deliver a package to zone c" (DeliverIntent naming no robot), "send a robot to zone d",
"send two robots to zone b", "send the east team to zone c" (FleetNavigateIntent), "send
the robots in zone a to the loading zone" (ZoneRobotsIntent), "send every idle robot to
zone c" (IdleRobotsIntent), "what is queued?" (TaskQueueIntent) and "cancel the delivery to
zone b" (CancelTaskIntent). The handlers read the slots, build an `Order`, hand it to the
desk and speak `skill.task_speech`'s sentence; the dispatcher picks the robots.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import deeds, dialog, prompts, task_speech
from skill.guard import confirm_first
from skill.handlers.desk_intent import DeskIntentHandler
from skill.responses import answer
from skill.slots import read_slot, spoken_number
from skill.task_desk import TaskRefused
from skill.vocabulary import capitalise
from vahr.dispatch import Order

if TYPE_CHECKING:
    from ask_sdk_core.dispatch_components import AbstractRequestHandler
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import IntentRequest, Response

    from skill.runtime import SkillRuntime
    from skill.slots import SlotReading
    from skill.task_desk import TaskDesk


class _FleetHandler(DeskIntentHandler):
    """What every dispatch handler shares: the runtime, the desk, submitting an order."""

    def submit(self, handler_input: HandlerInput, order: Order, *, when_none: str) -> Response:
        """Hand `order` to the dispatcher and say what it did; `when_none` is said when no
        robot may go (no free robot in the zone, none idle)."""
        if self.desk is None:
            return answer(handler_input, prompts.NO_DISPATCHER)
        question = confirm_first(handler_input, self.runtime)
        if question is not None:
            return question
        try:
            submission = self.desk.submit(order)
        except TaskRefused as err:
            if err.status == 404:  # a stack without the dispatcher's routes
                return answer(handler_input, prompts.NO_DISPATCHER)
            if err.error == "none_free":
                return answer(handler_input, when_none)
            deeds.failed(f"the dispatcher refused: {err}")
            if err.error == "zone_closed":
                zone = self.runtime.vocabulary.zone(order.zone)
                return answer(handler_input, capitalise(prompts.ZONE_CLOSED.format(zone=zone)))
            return answer(handler_input, prompts.DISPATCH_REFUSED.format(reason=str(err)))
        deeds.submitted(submission)
        speech = task_speech.submission_report(self.runtime.vocabulary, order, submission)
        return answer(handler_input, speech)

    def zone(self, handler_input: HandlerInput, name: str = "zone") -> SlotReading:
        return dialog.zone(handler_input, self.runtime, name)


class FleetDeliverHandler(_FleetHandler):
    """DeliverIntent: a delivery to a zone that names no robot goes to the fleet, which
    picks the robot; any other (a robot named, or no zone said) to `named`, as before."""

    intent_name = "DeliverIntent"

    def __init__(
        self, runtime: SkillRuntime, desk: TaskDesk | None, *, named: AbstractRequestHandler
    ) -> None:
        super().__init__(runtime, desk)
        self.named = named

    def handle(self, handler_input: HandlerInput) -> Response:
        zone = self.zone(handler_input)
        robot = dialog.robot(handler_input, self.runtime, "robot")
        # "deliver a package" alone, or a robot that did not resolve: the named handler
        # asks which robot, as it always did.
        if not robot.missing or zone.missing:
            response = self.named.handle(handler_input)
            assert response is not None  # every handler of this skill answers
            return response
        if dialog.delivery_zone_problem(zone):
            return dialog.ask_zone(
                handler_input,
                self.runtime,
                zone,
                deliverable=True,
                preface=prompts.LOADING_IS_NOT_A_DESTINATION if zone.id else "",
            )
        assert zone.id is not None
        order = Order(kind="deliver", zone=zone.id)
        return self.submit(handler_input, order, when_none=prompts.NO_FREE_ROBOT)


class FleetNavigateIntentHandler(_FleetHandler):
    """ "send a robot / two robots / the east team to zone c"."""

    intent_name = "FleetNavigateIntent"

    def handle(self, handler_input: HandlerInput) -> Response:
        zone = self.zone(handler_input)
        if zone.id is None:
            return dialog.ask_zone(handler_input, self.runtime, zone)
        group, refusal = dialog.group(handler_input, self.runtime)
        if refusal:
            return answer(handler_input, refusal)
        count, refusal = self._count(handler_input, group)
        if refusal:
            return answer(handler_input, refusal)
        order = Order(kind="navigate", zone=zone.id, count=count, group=group)
        return self.submit(handler_input, order, when_none=prompts.NO_FREE_ROBOT)

    def _count(self, handler_input: HandlerInput, group: str | None) -> tuple[int | None, str]:
        """How many robots: 1 when no count was said ("a robot"), except for a group (every
        member); or what to say when more were asked for than there are."""
        fleet = self.runtime.fleet
        members = next((len(g.robots) for g in fleet.groups if g.id == group), len(fleet.robots))
        owner = "The fleet" if group is None else capitalise(dialog.group_name(self.runtime, group))
        reading = read_slot(
            _intent(handler_input),
            "count",
            {str(n) for n in range(1, 100)},
            lambda heard: _number(heard),
        )
        if reading.missing:
            return (None if group is not None else 1), ""
        count = int(reading.id) if reading.id is not None else spoken_number(reading.heard)
        if count is None:
            return 1, ""
        if count > members:
            return None, prompts.TOO_MANY.format(owner=owner, most=members, count=count)
        return count, ""


class ZoneRobotsIntentHandler(_FleetHandler):
    """ "send the robots in zone a to the loading zone": the free robots reported there."""

    intent_name = "ZoneRobotsIntent"

    def handle(self, handler_input: HandlerInput) -> Response:
        origin = self.zone(handler_input, "origin")
        if origin.id is None:
            return dialog.ask_zone(handler_input, self.runtime, origin, prompts.ASK_ORIGIN)
        zone = self.zone(handler_input)
        if zone.id is None:
            return dialog.ask_zone(handler_input, self.runtime, zone)
        order = Order(kind="navigate", zone=zone.id, origin=origin.id)
        origin_name = self.runtime.vocabulary.zone(origin.id)
        return self.submit(
            handler_input, order, when_none=prompts.NO_ROBOT_IN_ZONE.format(zone=origin_name)
        )


class IdleRobotsIntentHandler(_FleetHandler):
    """ "send every idle robot to zone c"."""

    intent_name = "IdleRobotsIntent"

    def handle(self, handler_input: HandlerInput) -> Response:
        zone = self.zone(handler_input)
        if zone.id is None:
            return dialog.ask_zone(handler_input, self.runtime, zone)
        order = Order(kind="navigate", zone=zone.id, idle=True)
        return self.submit(handler_input, order, when_none=prompts.NO_IDLE_ROBOT)


class TaskQueueIntentHandler(_FleetHandler):
    """ "what is queued?"."""

    intent_name = "TaskQueueIntent"

    def handle(self, handler_input: HandlerInput) -> Response:
        if self.desk is None:
            return answer(handler_input, prompts.NO_DISPATCHER)
        try:
            tasks = self.desk.tasks()
            closed = self.desk.closed_zones() if tasks else []
        except TaskRefused:  # a stack without the dispatcher's routes
            return answer(handler_input, prompts.NO_DISPATCHER)
        report = task_speech.queue_report(self.runtime.vocabulary, tasks, closed=closed)
        return answer(handler_input, report)


class CancelTaskIntentHandler(_FleetHandler):
    """ "cancel the delivery to zone b": every open task there (a robot holding one is
    stopped), said with how many and which robots stopped."""

    intent_name = "CancelTaskIntent"

    def handle(self, handler_input: HandlerInput) -> Response:
        zone = self.zone(handler_input)
        if zone.id is None:
            return dialog.ask_zone(handler_input, self.runtime, zone)
        if self.desk is None:
            return answer(handler_input, prompts.NO_DISPATCHER)
        vocabulary = self.runtime.vocabulary
        try:
            tasks = self.desk.tasks()
        except TaskRefused:  # a stack without the dispatcher's routes
            return answer(handler_input, prompts.NO_DISPATCHER)
        cancelled = []
        for task, place in task_speech.tasks_to_cancel(tasks, zone.id):
            done = self.desk.cancel(task.id)
            if done is not None:  # else it ended meanwhile
                cancelled.append((done, place))
        if not cancelled:
            return answer(
                handler_input, prompts.NOTHING_TO_CANCEL.format(zone=vocabulary.zone(zone.id))
            )
        for task, _ in cancelled:
            deeds.cancelled_task(task)
        return answer(handler_input, task_speech.cancel_report(vocabulary, cancelled))


def _intent(handler_input: HandlerInput):  # type: ignore[no-untyped-def]
    request: IntentRequest = handler_input.request_envelope.request  # type: ignore[assignment]
    return request.intent


def _number(heard: str) -> str | None:
    value = spoken_number(heard)
    return str(value) if value is not None else None
