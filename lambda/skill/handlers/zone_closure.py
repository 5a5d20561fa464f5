"""CloseZoneIntent and OpenZoneIntent: "close zone b", "open zone b" (docs/floors.md).

The dispatcher keeps which zones are closed (`TaskDesk.set_zone`): no robot is sent into a
closed zone, queued tasks for it wait, robots leave it and drive around its area. Closing
and opening change the service of the whole fleet: a supervisor's commands (`skill.access`),
confirmed by their asker first (`skill.guard.confirm_first`) and recorded in the trail.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import deeds, dialog, prompts, task_speech
from skill.guard import confirm_first
from skill.handlers.desk_intent import DeskIntentHandler
from skill.responses import answer
from skill.task_desk import TaskRefused

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response


class _ZoneHandler(DeskIntentHandler):
    """Close or open the zone named in the request."""

    closes = True

    def handle(self, handler_input: HandlerInput) -> Response:
        zone = dialog.zone(handler_input, self.runtime, "zone")
        if zone.id is None:
            return dialog.ask_zone(handler_input, self.runtime, zone)
        if self.desk is None:
            return answer(handler_input, prompts.NO_ZONE_DESK)
        question = confirm_first(handler_input, self.runtime)
        if question is not None:
            return question
        try:
            change = self.desk.set_zone(zone.id, closed=self.closes)
        except TaskRefused as err:
            deeds.failed(f"the dispatcher refused: {err}")
            if err.status == 404:  # a stack without the dispatcher's zone routes
                return answer(handler_input, prompts.NO_ZONE_DESK)
            return answer(handler_input, prompts.DISPATCH_REFUSED.format(reason=str(err)))
        deeds.zone_changed(change)
        return answer(
            handler_input, task_speech.zone_change_report(self.runtime.vocabulary, change)
        )


class CloseZoneIntentHandler(_ZoneHandler):
    """ "close zone b": no robot goes there until it opens."""

    intent_name = "CloseZoneIntent"
    closes = True


class OpenZoneIntentHandler(_ZoneHandler):
    """ "open zone b": robots may go there again; what waited for it goes."""

    intent_name = "OpenZoneIntent"
    closes = False
