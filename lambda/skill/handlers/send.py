"""The step every robot-command handler ends with: send, wait for robots, speak the outcome
(a fleet-wide command is confirmed first, `skill.guard.confirm_first`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import battery_speech, deeds, prompts, session, speech
from skill.commands import publication
from skill.guard import confirm_first
from skill.responses import answer
from skill.service_guard import out_of_service
from skill.vocabulary import FLEET, capitalise
from skill.zone_guard import closed_zone

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Response

    from skill.runtime import SkillRuntime
    from skill.task_desk import TaskDesk


def send_and_report(
    handler_input: HandlerInput,
    runtime: SkillRuntime,
    action: str,
    target: str,
    params: dict[str, object] | None = None,
    *,
    desk: TaskDesk | None = None,
) -> Response:
    """Publish `action` to one robot (or the fleet) and say what the robots answered; a
    command into a zone the dispatcher (`desk`) says is closed, or to a robot it says is
    out of service (any command but a stop), is not sent, and a fleet-wide one is
    confirmed by its asker first."""
    refusal = service_reply(runtime, desk, action, [target])
    if refusal is not None:
        return answer(handler_input, refusal)
    zone = (params or {}).get("zone")
    refused = closed_reply(runtime, desk, [zone if isinstance(zone, str) else None])
    if refused is not None:
        return answer(handler_input, refused)
    question = confirm_first(handler_input, runtime)
    if question is not None:
        return question
    item = publication(runtime.fleet, action, target, params)
    answers = runtime.robots.send([item])
    session.remember(handler_input, item)
    return answer(handler_input, speech.command_report(runtime.vocabulary, item, answers))


def service_reply(
    runtime: SkillRuntime, desk: TaskDesk | None, action: str, targets: list[str]
) -> str | None:
    """What to say instead of sending `action` to `targets` (things, or the fleet) when
    some of them are out of service; None for a stop, which always goes out."""
    if action == "stop":
        return None
    things = [
        thing
        for target in targets
        for thing in (runtime.fleet.robot_things if target == FLEET else (target,))
    ]
    out = out_of_service(desk, things)
    if not out:
        return None
    deeds.failed("out of service: " + ", ".join(out))
    return battery_speech.refused(runtime.vocabulary, out)


def closed_reply(
    runtime: SkillRuntime, desk: TaskDesk | None, zones: list[str | None]
) -> str | None:
    """What to say instead of sending, when one of `zones` is closed now."""
    closed = closed_zone(desk, zones)
    if closed is None:
        return None
    return capitalise(prompts.ZONE_CLOSED.format(zone=runtime.vocabulary.zone(closed)))
