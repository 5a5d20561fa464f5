"""The step every robot-command handler ends with: send, wait for robots, speak the outcome
(a fleet-wide command is confirmed first, `skill.guard.confirm_first`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import session, speech
from skill.commands import publication
from skill.guard import confirm_first
from skill.responses import answer

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime


def send_and_report(
    handler_input: HandlerInput,
    runtime: SkillRuntime,
    action: str,
    target: str,
    params: dict[str, object] | None = None,
) -> Response:
    """Publish `action` to one robot (or the fleet) and say what the robots answered."""
    question = confirm_first(handler_input, runtime)
    if question is not None:
        return question
    item = publication(runtime.fleet, action, target, params)
    answers = runtime.robots.send([item])
    session.remember(handler_input, item)
    return answer(handler_input, speech.command_report(runtime.vocabulary, item, answers))
