"""The base of the handlers that ask the fleet dispatcher: one intent each, the skill's
runtime and the dispatcher's desk (None where no dispatcher runs, which each handler says
in its own words)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ask_sdk_core.dispatch_components import AbstractRequestHandler
from ask_sdk_core.utils import is_intent_name

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput

    from skill.runtime import SkillRuntime
    from skill.task_desk import TaskDesk


class DeskIntentHandler(AbstractRequestHandler):
    """Handles the intent named `intent_name` with the runtime and the desk."""

    intent_name = ""

    def __init__(self, runtime: SkillRuntime, desk: TaskDesk | None) -> None:
        self.runtime = runtime
        self.desk = desk

    def can_handle(self, handler_input: HandlerInput) -> bool:
        return bool(is_intent_name(self.intent_name)(handler_input))
